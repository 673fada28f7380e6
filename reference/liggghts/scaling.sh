#!/bin/sh
# Two-thread scaling of polydem beside two-process scaling of LIGGGHTS on one sphere-bed variant, in
# alternating rounds, each round with the core-to-core round trip just before and after it (see
# polydem::host::core_round_trip_ns: the host moves the two virtual CPUs between one die and two).
# Usage: sh scaling.sh [ROUNDS] [VARIANT]   (defaults: 6 rounds, a_hertz_5ms). The recorded file
# out/scaling_a_hertz_5ms.txt holds two runs one after the other: `sh scaling.sh 10`, then `sh scaling.sh 30`.
# Per round, one line: UTC time, round trips before/after (ns), polydem wall times (s) on 1 and 2 threads
# and their ratio (examples/sphere_bed_speed: SphereSim::run_steps, the suite's driver), LIGGGHTS loop
# times (s) on 1 and 2 MPI processes and their ratio. LIGGGHTS runs in.penetration with `processors * 1 1`
# added, so that two processes split the box across x into halves of the bed (its default split cuts the
# tall box, z from -0.2 to 0.3 m, at z = 0.05 m, inside the bed: 1.17x on two processes in one run, 2026-11-27).
# Needs: cargo, liggghts, mpirun (Debian: apt-get install -y liggghts, which brings Open MPI).
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT="$HERE/../.."
BED="$HERE/../sphere_bed"
ROUNDS=${1:-6}
V=${2:-a_hertz_5ms}
(cd "$ROOT" && cargo build -q --release --example sphere_bed_speed --example core_round_trip)
SPEED="$ROOT/target/release/examples/sphere_bed_speed"
TRIP="$ROOT/target/release/examples/core_round_trip"
SCENE="$ROOT/scenes/sphere_bed_$V.toml"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
set -- $(python3 "$HERE/make_data.py" "$V" "$WORK/bed.data")
PID=$1
VARS=$(python3 "$BED/derived.py" --liggghts-vars "$V")
LAW=$(python3 -c "import json;print(json.load(open('$BED/scene.json'))['variants']['$V']['law'])")
sed 's/^boundary .*/&\nprocessors      * 1 1/' "$HERE/in.penetration" > "$WORK/in.mpi"
liggghts_loop() {
  # shellcheck disable=SC2086
  (cd "$HERE" && mpirun --allow-run-as-root -np "$1" liggghts -in "$WORK/in.mpi" $VARS \
      -var lawfile "in.law_$LAW" -var datafile "$WORK/bed.data" -var pid "$PID" \
      -var outfile "$WORK/print.txt" -log "$WORK/log.liggghts" -echo none -screen none >/dev/null)
  grep 'Loop time' "$WORK/log.liggghts" | tail -1 | awk '{print $4}'
}
polydem_wall() {
  "$SPEED" --steps 1000000 --threads "$1" "$SCENE" | grep -o 'wall [0-9.]* s' | awk '{print $2}'
}
ratio() { python3 -c "print(f'{$1 / $2:.3f}')"; }
echo "# reference/liggghts/scaling.sh $ROUNDS $V; started $(date -u +%Y-%m-%dT%H:%M:%SZ)"
echo "# polydem $(cd "$ROOT" && git rev-parse --short HEAD 2>/dev/null || echo unknown); LIGGGHTS-PUBLIC $(dpkg-query -W -f='${Version}' liggghts 2>/dev/null || echo unknown); $(mpirun --version 2>/dev/null | head -1)"
echo "# machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'); load average at start $(cut -d' ' -f1-3 /proc/loadavg)"
echo "# utc round_trip_before_ns round_trip_after_ns polydem_1 polydem_2 polydem_ratio liggghts_1 liggghts_2 liggghts_ratio"
for r in $(seq 1 "$ROUNDS"); do
  before=$("$TRIP" | sed "s/ ns//g")
  p1=$(polydem_wall 1); p2=$(polydem_wall 2)
  l1=$(liggghts_loop 1); l2=$(liggghts_loop 2)
  after=$("$TRIP" | sed "s/ ns//g")
  echo "$(date -u +%H:%M:%S) $before $after $p1 $p2 $(ratio "$p1" "$p2") $l1 $l2 $(ratio "$l1" "$l2")"
done
