"""A batch of random convex-polyhedron pairs through `polydem.contact_batch` (GJK/EPA, in parallel, GIL
released), each answer compared with the exact separating-axis oracle `polydem.contact_oracle`.

    python python/examples/contact_vs_oracle.py [N_PAIRS] [SEED]

Prints the number of pairs whose status differs from the oracle's and the largest depth/distance error
relative to the pair's size; exits 1 if any status differs or an error exceeds 1e-9 of the size.
"""

import sys
import time

import numpy as np

import polydem


def random_hull(rng, n):
    """A convex polyhedron from n points on a randomly stretched sphere, size about 1."""
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    return polydem.ConvexPolyhedron.from_points(p * rng.uniform(0.4, 1.0, size=3))


def random_quaternions(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 500
    rng = np.random.default_rng(int(sys.argv[2]) if len(sys.argv) > 2 else 1)
    shapes_a = [random_hull(rng, rng.integers(6, 30)) for _ in range(n)]
    shapes_b = [random_hull(rng, rng.integers(6, 30)) for _ in range(n)]
    # Centres 0.5–2.5 apart: overlapping, touching-near and separated pairs.
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    pose_a = (np.zeros((n, 3)), random_quaternions(rng, n))
    pose_b = (direction * rng.uniform(0.5, 2.5, size=(n, 1)), random_quaternions(rng, n))

    start = time.perf_counter()
    batch = polydem.contact_batch(shapes_a, shapes_b, pose_a, pose_b)
    batch_s = time.perf_counter() - start

    wrong, worst = 0, 0.0
    for i in range(n):
        pa, pb = (pose_a[0][i], pose_a[1][i]), (pose_b[0][i], pose_b[1][i])
        exact = polydem.contact_oracle(shapes_a[i], shapes_b[i], pa, pb)
        size = 2.0 * max(shapes_a[i].bounding_radius, shapes_b[i].bounding_radius)
        if batch["status"][i] != exact.status:
            wrong += 1
            print(f"pair {i}: GJK/EPA says {batch['status'][i]}, the oracle {exact.status}")
        value = batch["depth"][i] if exact.status == "overlap" else batch["distance"][i]
        reference = exact.depth if exact.status == "overlap" else exact.distance
        worst = max(worst, abs(value - reference) / size)
    statuses = {s: int(np.sum(batch["status"] == s)) for s in ("overlap", "touching", "separated")}
    print(f"{n} pairs {statuses}: {wrong} statuses differ from the oracle; largest depth/distance error "
          f"{worst:.2e} of the size; batch {1e9 * batch_s / n:.0f} ns per pair")
    sys.exit(1 if wrong or worst > 1e-9 else 0)


if __name__ == "__main__":
    main()
