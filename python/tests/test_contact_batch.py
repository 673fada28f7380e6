"""The batched contact query equals the single queries bit for bit, broadcasts a single shape, and
refuses inputs of mismatched lengths with a message naming them."""

import numpy as np
import pytest

import polydem


def random_rotations(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def test_batch_equals_single_queries_bit_for_bit():
    rng = np.random.default_rng(7)
    n = 200
    shapes = [polydem.ConvexPolyhedron.from_points(rng.normal(size=(rng.integers(4, 16), 3))) for _ in range(5)]
    shapes += [polydem.Sphere(0.4), polydem.Ellipsoid(0.6, 0.3, 0.2)]
    a = [shapes[i] for i in rng.integers(0, len(shapes), n)]
    b = [shapes[i] for i in rng.integers(0, len(shapes), n)]
    pos_a, pos_b = rng.normal(size=(n, 3)), rng.normal(size=(n, 3)) * 1.5
    q_a, q_b = random_rotations(rng, n), random_rotations(rng, n)
    batch = polydem.contact_batch(a, b, (pos_a, q_a), (pos_b, q_b))
    assert set(batch["status"]) >= {"overlap", "separated"}, set(batch["status"])
    for i in range(n):
        single = polydem.contact(a[i], b[i], (pos_a[i], q_a[i]), (pos_b[i], q_b[i]))
        assert (batch["status"][i], batch["solver"][i]) == (single.status, single.solver), i
        for key in ("depth", "distance"):
            assert batch[key][i] == getattr(single, key), (i, key, batch[key][i], getattr(single, key))
        for key in ("normal", "point_a", "point_b", "point"):
            assert batch[key][i].tolist() == getattr(single, key).tolist(), (i, key)


def test_a_single_shape_is_used_for_every_pair():
    cube = polydem.ConvexPolyhedron.from_points(
        np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    )
    gaps = np.array([0.1, 0.2, -0.05])
    positions = np.column_stack([1.0 + gaps, np.zeros(3), np.zeros(3)])
    quaternions = np.tile([1.0, 0.0, 0.0, 0.0], (3, 1))
    batch = polydem.contact_batch(cube, cube, None, (positions, quaternions))
    assert batch["status"].tolist() == ["separated", "separated", "overlap"]
    measured = np.where(batch["status"] == "overlap", -batch["depth"], batch["distance"])
    assert np.allclose(measured, gaps, rtol=0, atol=1e-12), f"gaps {measured}, expected {gaps}, tol 1e-12"
    assert batch["normal"].shape == (3, 3)


@pytest.mark.parametrize(
    "args, message",
    [
        (lambda s: ([s, s], [s, s, s]), "b has 3 entries but a has 2"),
        (lambda s: (s, s, None, (np.zeros((2, 3)), np.tile([1.0, 0, 0, 0], (3, 1)))), "2 positions but 3 quaternions"),
        (lambda s: (s, s, (np.zeros((2, 3)), [[1.0, 0, 0, 0], [2.0, 0, 0, 0]])), "pose_a quaternions[1]"),
        (lambda s: (s, s, (np.zeros((1, 3)) * np.nan, [[1.0, 0, 0, 0]])), "pose 0 has a non-finite value"),
        (lambda s: ([s, "no"], s), "a[1]: expected a Shape"),
    ],
)
def test_bad_batches(args, message):
    sphere = polydem.Sphere(1.0)
    with pytest.raises(ValueError) as err:
        polydem.contact_batch(*args(sphere))
    assert message in str(err.value), f"message {str(err.value)!r} should contain {message!r}"
