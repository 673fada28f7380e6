"""The cost per pair of `polydem.contact_batch` against the engine's own loop over the same pairs.

    RAYON_NUM_THREADS=1 python python/examples/contact_batch_speed.py [PAIRS.jsonl] [REPEATS]

Both sides build the hulls of every pair of the file first (outside the timing), then time the queries:
the Rust side is `examples/contact_loop.rs` (a plain loop on one thread, built here with cargo), the
Python side one `contact_batch` call over all pairs (with RAYON_NUM_THREADS=1, also one thread). Prints
the best of REPEATS of each, their ratio and the load average.
"""

import json
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

import polydem

REPO = pathlib.Path(__file__).resolve().parents[2]


def main():
    path = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "reference/contact/random.jsonl"
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 20
    lines = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    a = [polydem.ConvexPolyhedron.from_points(np.array(p["a"], dtype=float)) for p in lines]
    b = [polydem.ConvexPolyhedron.from_points(np.array(p["b"], dtype=float)) for p in lines]
    polydem.contact_batch(a, b)  # warms the thread pool
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        polydem.contact_batch(a, b)
        best = min(best, (time.perf_counter() - start) * 1e9 / len(lines))
    rust = subprocess.run(["cargo", "run", "--release", "--quiet", "--example", "contact_loop", "--", str(path),
                           str(repeats)], cwd=REPO, capture_output=True, text=True, check=True).stdout
    rust_ns = float(rust.split(":")[-1].split()[0])
    load = " ".join(f"{x:.2f}" for x in os.getloadavg())
    threads = os.environ.get("RAYON_NUM_THREADS", "all cores")
    print(f"{len(lines)} pairs of {path.name}, best of {repeats}; threads: {threads}; load average {load}")
    print(f"Rust loop       {rust_ns:10.1f} ns per pair")
    print(f"contact_batch   {best:10.1f} ns per pair   ({best / rust_ns:.3f} of the Rust loop)")


if __name__ == "__main__":
    main()
