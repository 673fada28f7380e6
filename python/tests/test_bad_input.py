"""Bad inputs raise a ValueError naming the problem; none crashes the interpreter."""

import numpy as np
import pytest

import polydem

CUBE = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)


@pytest.mark.parametrize(
    "points, message",
    [
        (np.zeros((4, 2)), "shape (N, 3), got shape (4, 2)"),
        (np.zeros(12), "got shape (12,)"),
        (np.zeros((2, 4, 3)), "got shape (2, 4, 3)"),
        (np.array([["a", "b", "c"]] * 4), "expected real numbers, got an array of dtype"),
        (np.zeros((4, 3), dtype=complex), "dtype complex128"),
        ([[0, 0, 0], [1, 0]], "not an array of numbers"),
        (np.vstack([CUBE[:3], [[np.nan, 0, 0]], CUBE[4:]]), "point 3 has a non-finite value"),
        (np.vstack([CUBE[:5], [[0, np.inf, 0]]]), "point 5 has a non-finite value"),
        (CUBE[:3], "too few points: 3 given"),
        (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float), "coplanar"),
    ],
)
def test_bad_points(points, message):
    with pytest.raises(ValueError, match=None) as err:
        polydem.ConvexPolyhedron.from_points(points)
    assert message in str(err.value), f"message {str(err.value)!r} should contain {message!r}"
    assert str(err.value).startswith("points: ")


def test_integer_points_are_taken():
    cube = polydem.ConvexPolyhedron.from_points(CUBE.astype(np.int32))
    assert cube.volume == polydem.ConvexPolyhedron.from_points(CUBE).volume


@pytest.mark.parametrize(
    "pose, message",
    [
        ("nonsense", "pose_b: expected a pair (position[3], quaternion[4]"),
        (([0, 0], [1, 0, 0, 0]), "pose_b position: expected an array of shape (3,), got shape (2,)"),
        (([0, 0, np.nan], [1, 0, 0, 0]), "pose_b position: element 2 is not finite"),
        (([0, 0, 0], [1, 0, 0]), "pose_b quaternion: expected an array of shape (4,)"),
        (([0, 0, 0], [2, 0, 0, 0]), "has norm 2, expected 1"),
        (([0, 0, 0], [0, 0, 0, 0]), "has norm 0, expected 1"),
    ],
)
def test_bad_poses(pose, message):
    cube = polydem.ConvexPolyhedron.from_points(CUBE)
    with pytest.raises(ValueError) as err:
        polydem.contact(cube, cube, None, pose)
    assert message in str(err.value), f"message {str(err.value)!r} should contain {message!r}"


@pytest.mark.parametrize("radius", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_sphere_radius(radius):
    with pytest.raises(ValueError, match="radius"):
        polydem.Sphere(radius)


@pytest.mark.parametrize("axes", [(0.0, 1.0, 1.0), (1.0, -1.0, 1.0), (1.0, 1.0, float("nan"))])
def test_bad_ellipsoid_axes(axes):
    with pytest.raises(ValueError, match="semi-axes"):
        polydem.Ellipsoid(*axes)


def test_not_a_shape():
    with pytest.raises(TypeError):
        polydem.contact("cube", polydem.Sphere(1.0))
