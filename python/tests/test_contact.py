"""Contact queries against closed forms, and against the Rust answer of `polydem contact` on a seeded
set of pairs (the same engine function: equal bit for bit)."""

import json

import numpy as np
import pytest

import polydem
from conftest import run

IDENTITY = [1.0, 0.0, 0.0, 0.0]
REL = 1e-9  # relative to the box size: GJK/EPA stop at 1e-13 of the size, far below this


def box(half_extents):
    hx, hy, hz = half_extents
    return polydem.ConvexPolyhedron.from_points(
        np.array([[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    )


@pytest.mark.parametrize("gap", [1e-3, 0.02, 0.3])
def test_two_boxes_apart_by_a_gap(gap):
    h = np.array([0.05, 0.04, 0.03])
    a, b = box(h), box(h)
    x = 2 * h[0] + gap
    r = polydem.contact(a, b, ([0, 0, 0], IDENTITY), ([x, 0.01, -0.005], IDENTITY))
    tol = REL * 0.1
    assert r.status == "separated", f"gap {gap}: status {r.status}"
    assert abs(r.distance - gap) <= tol, f"gap {gap}: distance {r.distance}, expected {gap}, tol {tol:e}"
    assert r.depth == 0.0
    assert np.allclose(r.normal, [1, 0, 0], rtol=0, atol=1e-12), f"gap {gap}: normal {r.normal}"
    # Swapped, the normal turns over.
    s = polydem.contact(b, a, ([x, 0.01, -0.005], IDENTITY), ([0, 0, 0], IDENTITY))
    assert np.allclose(s.normal, [-1, 0, 0], rtol=0, atol=1e-12), f"gap {gap}: swapped normal {s.normal}"
    assert abs(s.distance - gap) <= tol


@pytest.mark.parametrize("penetration", [1e-4, 0.005, 0.02])
def test_two_boxes_overlapping(penetration):
    h = np.array([0.05, 0.04, 0.03])
    a, b = box(h), box(h)
    x = 2 * h[0] - penetration
    r = polydem.contact(a, b, ([0, 0, 0], IDENTITY), ([x, 0.01, -0.005], IDENTITY))
    tol = REL * 0.1
    assert r.status == "overlap", f"penetration {penetration}: status {r.status}"
    assert abs(r.depth - penetration) <= tol, (
        f"penetration {penetration}: depth {r.depth}, expected {penetration}, tol {tol:e}"
    )
    assert r.distance == 0.0
    assert np.allclose(r.normal, [1, 0, 0], rtol=0, atol=1e-12), f"normal {r.normal}"
    # c1 − c2 = δ n and c_M their midpoint.
    assert np.allclose(r.point_a - r.point_b, r.depth * r.normal, rtol=0, atol=tol)
    assert np.array_equal(r.point, 0.5 * (r.point_a + r.point_b)) or np.allclose(
        r.point, 0.5 * (r.point_a + r.point_b), rtol=0, atol=1e-15
    )


def test_spheres_and_ellipsoid_closed_forms():
    r = polydem.contact(polydem.Sphere(0.5), polydem.Sphere(0.25), None, ([1.0, 0, 0], IDENTITY))
    assert r.status == "separated" and abs(r.distance - 0.25) <= 1e-12, r
    # An ellipsoid's semi-axis a along x against a sphere on the x axis: the gap is x − a − radius.
    e = polydem.contact(polydem.Ellipsoid(0.5, 0.2, 0.1), polydem.Sphere(0.1), None, ([0.55, 0, 0], IDENTITY))
    assert e.status == "overlap", e
    assert abs(e.depth - 0.05) <= 1e-9 * 0.5, f"ellipsoid–sphere depth {e.depth}, expected 0.05, tol 5e-10"


def test_pose_rotation_places_the_shape():
    # A unit cube turned by 90° about z around its corner at the origin occupies x in [-1, 0].
    points = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    cube = polydem.ConvexPolyhedron.from_points(points)
    half = np.sqrt(0.5)
    r = polydem.contact(cube, cube, ([0, 0, 0], [half, 0, 0, half]), ([0.25, 0, 0], IDENTITY))
    assert r.status == "separated" and abs(r.distance - 0.25) <= 1e-12, r


def random_pairs(seed, count):
    """Seeded point-cloud pairs, coordinates rounded to 6 decimals: serde_json (without its
    `float_roundtrip` feature, as the CLI builds it) may read a 17-digit decimal one ulp off, while short
    decimals are read exactly by both sides, so the comparison is of the engine, not of the parsers."""
    rng = np.random.default_rng(seed)
    pairs = []
    for i in range(count):
        a = rng.normal(size=(rng.integers(4, 12), 3)) * rng.uniform(0.5, 2.0)
        b = rng.normal(size=(rng.integers(4, 12), 3)) * rng.uniform(0.5, 2.0) + rng.normal(size=3) * 2.0
        pairs.append((np.round(a, 6), np.round(b, 6)))
    return pairs


def test_equal_to_polydem_contact_bit_for_bit(tmp_path, polydem_bin):
    pairs = random_pairs(seed=20240, count=60)
    lines = [json.dumps({"id": i, "a": a.tolist(), "b": b.tolist()}) for i, (a, b) in enumerate(pairs)]
    (tmp_path / "pairs.jsonl").write_text("\n".join(lines) + "\n")
    run([str(polydem_bin), "contact", str(tmp_path / "pairs.jsonl"), "--out", str(tmp_path / "out.jsonl")])
    answers = [json.loads(line) for line in (tmp_path / "out.jsonl").read_text().splitlines()]
    assert len(answers) == len(pairs)
    statuses = set()
    for (a, b), rust in zip(pairs, answers):
        assert "error" not in rust, rust
        py = polydem.contact(polydem.ConvexPolyhedron.from_points(a), polydem.ConvexPolyhedron.from_points(b))
        statuses.add(py.status)
        assert (py.status, py.solver) == (rust["status"], rust["solver"]), (rust["id"], py, rust)
        for field in ("depth", "distance"):
            assert getattr(py, field) == rust[field], (rust["id"], field, getattr(py, field), rust[field])
        for field in ("normal", "point_a", "point_b", "point"):
            assert getattr(py, field).tolist() == rust[field], (rust["id"], field, getattr(py, field), rust[field])
    assert statuses >= {"overlap", "separated"}, f"the seeded set should cover both cases, got {statuses}"
