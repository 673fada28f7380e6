"""Mass properties of shapes against closed forms, in the frame the shape was given in."""

import math

import numpy as np
import pytest

import polydem

REL = 1e-12  # relative to the quantity's scale: rounding of the hull and inertia sums only


def box_points(half_extents, centre=(0.0, 0.0, 0.0), rotation=np.eye(3)):
    hx, hy, hz = half_extents
    corners = np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    return corners @ rotation.T + np.asarray(centre)


def rotation_about(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def assert_close(measured, expected, scale, what):
    measured, expected = np.asarray(measured, float), np.asarray(expected, float)
    tol = REL * scale
    assert np.all(np.abs(measured - expected) <= tol), (
        f"{what}: measured {measured}, expected {expected}, tolerance {tol:e}"
    )


def test_unit_cube_volume_centroid_and_inertia():
    points = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    cube = polydem.ConvexPolyhedron.from_points(points)
    # A cube of side s per unit density: V = s³, I = V s² / 6 about every axis through the centroid.
    assert_close(cube.volume, 1.0, 1.0, "unit cube volume")
    assert_close(cube.centroid, [0.5, 0.5, 0.5], 1.0, "unit cube centroid")
    assert_close(cube.principal_moments, [1 / 6] * 3, 1 / 6, "unit cube principal moments")
    assert cube.num_faces == 6, f"unit cube faces: measured {cube.num_faces}, expected 6"
    assert cube.vertices.shape == (8, 3)


@pytest.mark.parametrize("angle", [0.0, 0.3, 1.1])
def test_cuboid_moments_and_axes_after_a_rotation(angle):
    h = np.array([0.05, 0.04, 0.03])
    rot = rotation_about([1.0, 2.0, -0.5], angle)
    box = polydem.ConvexPolyhedron.from_points(box_points(h, centre=(1.0, -2.0, 0.5), rotation=rot))
    sides = 2 * h
    volume = np.prod(sides)
    # I_x = V (b² + c²) / 12 for sides a, b, c; ascending order here is z, y, x... computed, then sorted.
    moments = volume / 12 * np.array(
        [sides[1] ** 2 + sides[2] ** 2, sides[0] ** 2 + sides[2] ** 2, sides[0] ** 2 + sides[1] ** 2]
    )
    order = np.argsort(moments)
    assert_close(box.volume, volume, volume, f"cuboid volume, angle {angle}")
    assert_close(box.centroid, [1.0, -2.0, 0.5], 1.0, f"cuboid centroid, angle {angle}")
    assert_close(box.principal_moments, moments[order], moments.max(), f"cuboid moments, angle {angle}")
    # Column k of the axes is the box's own axis of moment k, turned by the rotation (up to sign).
    axes = box.principal_axes
    for k, body_axis in enumerate(order):
        alignment = abs(axes[:, k] @ rot[:, body_axis])
        assert_close(alignment, 1.0, 1e4, f"cuboid axis {k} alignment, angle {angle}")


def test_sphere_and_ellipsoid_closed_forms():
    r = 0.3
    sphere = polydem.Sphere(r)
    v = 4 / 3 * math.pi * r**3
    assert_close(sphere.volume, v, v, "sphere volume")
    assert_close(sphere.principal_moments, [2 / 5 * v * r**2] * 3, v * r**2, "sphere moments")
    assert sphere.radius == r

    a, b, c = 0.5, 0.2, 0.1
    ell = polydem.Ellipsoid(a, b, c)
    v = 4 / 3 * math.pi * a * b * c
    moments = np.sort(v / 5 * np.array([b**2 + c**2, a**2 + c**2, a**2 + b**2]))
    assert_close(ell.volume, v, v, "ellipsoid volume")
    assert_close(ell.principal_moments, moments, moments.max(), "ellipsoid moments")
    assert_close(ell.semi_axes, [a, b, c], a, "ellipsoid semi-axes")
