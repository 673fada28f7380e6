"""The cost per pair of `polydem.contact_batch` against the engine's own loop over the same pairs.

    python python/examples/contact_batch_speed.py [PAIRS.jsonl] [REPEATS] [--rounds N]
    python python/examples/contact_batch_speed.py [PAIRS.jsonl] --instructions [--batches K]

Both sides build the hulls of every pair of the file first (outside the measurement), then query them:
the Rust side is `examples/contact_loop.rs` (a plain loop on one thread, built here with cargo), the
Python side one `contact_batch` call over all pairs on one rayon thread (RAYON_NUM_THREADS=1 is set for
it). The default pairs are the 420 of `reference/contact/random.jsonl`.

Time (default): N rounds (default 5), each REPEATS (default 20) passes of either side, one after the
other so that both see the same load; prints each round's ns per pair (best and mean, and the CPU time
of the Python process over its passes) and the ratio of the best, then the median ratio and the load
average. On a shared machine, the instruction count is the figure to compare.

Instructions (`--instructions`, needs valgrind): each side runs under callgrind once with one pass over
the pairs and once with K + 1 (default K = 10); the difference divided by K times the pair count is the
instructions per pair, free of start-up, hull building and the interpreter.
"""

import argparse
import json
import os
import pathlib
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import polydem

REPO = pathlib.Path(__file__).resolve().parents[2]
LOOP = REPO / "target" / "release" / "examples" / "contact_loop"
# One rayon thread for the batch (the loop has one), and no OpenBLAS threads, whose start-up spinning
# numpy would otherwise add to the measured process.
ENV = {"RAYON_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}


def shapes(path):
    lines = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    a = [polydem.ConvexPolyhedron.from_points(np.array(p["a"], dtype=float)) for p in lines]
    b = [polydem.ConvexPolyhedron.from_points(np.array(p["b"], dtype=float)) for p in lines]
    return a, b


def rust_ns(path, repeats):
    """The best and the mean ns per pair of the Rust loop."""
    out = subprocess.run([str(LOOP), str(path), str(repeats)], capture_output=True, text=True, check=True)
    best, mean = re.search(r"([\d.]+) ns per pair \(mean ([\d.]+)\)", out.stdout).groups()
    return float(best), float(mean)


def timed(path, repeats, rounds):
    a, b = shapes(path)
    polydem.contact_batch(a, b)  # starts the thread pool
    ratios = []
    load = os.getloadavg()
    for _ in range(rounds):
        best, wall, cpu = float("inf"), time.perf_counter(), time.process_time()
        for _ in range(repeats):
            start = time.perf_counter()
            polydem.contact_batch(a, b)
            best = min(best, (time.perf_counter() - start) * 1e9 / len(a))
        mean = (time.perf_counter() - wall) * 1e9 / (repeats * len(a))
        cpu = (time.process_time() - cpu) * 1e9 / (repeats * len(a))
        rust, rust_mean = rust_ns(path, repeats)
        ratios.append(best / rust)
        print(f"ns per pair, best (mean): contact_batch {best:7.1f} ({mean:7.1f}, CPU {cpu:7.1f})   "
              f"Rust loop {rust:7.1f} ({rust_mean:7.1f})   ratio of the best {best / rust:.3f}")
    load = " ".join(f"{(x + y) / 2:.2f}" for x, y in zip(load, os.getloadavg()))
    print(f"{len(a)} pairs of {path.name}, {rounds} rounds of best of {repeats}, one thread; median ratio "
          f"{statistics.median(ratios):.3f} (range {min(ratios):.3f}-{max(ratios):.3f}); load average {load} "
          f"on {os.cpu_count()} cores")


def instructions(command):
    """The instructions callgrind counts for `command` (all threads)."""
    with tempfile.TemporaryDirectory() as tmp:
        done = subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={tmp}/out", *command],
                              capture_output=True, text=True, check=True, env={**os.environ, **ENV})
    return int(re.search(r"Collected : (\d+)", done.stderr).group(1))


def counted(path, batches):
    n = sum(1 for line in path.read_text().splitlines() if line.strip())
    me = [sys.executable, __file__, str(path), "--passes"]
    per_pair = {}
    for name, command in (("contact_batch", me), ("Rust loop", [str(LOOP), str(path)])):
        one, many = (instructions([*command, str(k)]) for k in (1, batches + 1))
        per_pair[name] = (many - one) / (batches * n)
        print(f"{name:14} {per_pair[name]:9.0f} instructions per pair")
    ratio = per_pair["contact_batch"] / per_pair["Rust loop"]
    print(f"{n} pairs of {path.name}, {batches} passes counted by callgrind: ratio {ratio:.3f}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("pairs", nargs="?", type=pathlib.Path, default=REPO / "reference/contact/random.jsonl")
    parser.add_argument("repeats", nargs="?", type=int, default=20)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--instructions", action="store_true", help="count instructions with callgrind")
    parser.add_argument("--batches", type=int, default=10, help="passes counted with --instructions")
    parser.add_argument("--passes", type=int, help=argparse.SUPPRESS)  # the counted child: K batches
    args = parser.parse_args()
    if args.passes is not None:
        a, b = shapes(args.pairs)
        for _ in range(args.passes):
            polydem.contact_batch(a, b)
        return
    subprocess.run(["cargo", "build", "--release", "--quiet", "--example", "contact_loop"], cwd=REPO, check=True)
    if args.instructions:
        counted(args.pairs, args.batches)
    else:
        if any(os.environ.get(k) != v for k, v in ENV.items()):
            # Both thread pools are sized when they start: run again with the environment set.
            os.execve(sys.executable, [sys.executable, *sys.argv], {**os.environ, **ENV})
        timed(args.pairs, args.repeats, args.rounds)


if __name__ == "__main__":
    main()
