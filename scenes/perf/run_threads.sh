#!/usr/bin/env sh
# Throughput of the step on 1 and 2 threads on the perf scenes (10^4 polyhedra settling, the
# same bed struck by a steel sphere at 10 m/s, 10^4 spheres); see examples/perf_threads.rs for the scenes
# and what is printed (wall and CPU time, particle-steps/s, contacts/s, stage timers, load average, and
# whether 2 threads end in the bit-identical state). Run from the repository root on a quiet machine:
#     sh scenes/perf/run_threads.sh [--steps N] [--warm-up N] [--threads 1,2] [--scenes poly,poly_projectile,spheres]
#                                   [--repeat N] [--profile]
# The quiet-machine re-measurement of the ratios (median and range over seven back-to-back repeats):
#     sh scenes/perf/run_threads.sh --steps 1000 --warm-up 1000 --repeat 7
# The scenes are built in code from a fixed seed (nothing to generate or commit).
set -eu
cargo build --release --example perf_threads
exec ./target/release/examples/perf_threads "$@"
