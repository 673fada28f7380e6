#!/bin/sh
# Run the sphere-bed penetration variants in LIGGGHTS (serial, one process) and write
# out/<variant>.csv and out/<variant>.log. Usage: sh run.sh [variant ...]
# (default: every variant of ../sphere_bed/scene.json). Installs liggghts if missing.
# Environment: OUT_DIR (default: out/ here) receives the outputs; NICE (default 10) is the niceness of
# the run (the validation suite's full profile re-runs with OUT_DIR under its own output and NICE=0, the
# priority of its polydem run).
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
BED="$HERE/../sphere_bed"
if ! command -v liggghts >/dev/null 2>&1; then
  apt-get install -y liggghts
fi
VARIANTS=${*:-$(python3 -c "import json;print(' '.join(json.load(open('$BED/scene.json'))['variants']))")}
OUT_DIR=${OUT_DIR:-$HERE/out}
NICE=${NICE:-10}
mkdir -p "$OUT_DIR"
CPU=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')
for V in $VARIANTS; do
  WORK=$(mktemp -d)
  set -- $(python3 "$HERE/make_data.py" "$V" "$WORK/bed.data")
  PID=$1; Z0=$2; MASS=$3
  VARS=$(python3 "$BED/derived.py" --liggghts-vars "$V")
  LAW=$(python3 -c "import json;print(json.load(open('$BED/scene.json'))['variants']['$V']['law'])")
  CMD="liggghts -in in.penetration $VARS -var lawfile in.law_$LAW -var datafile bed.data -var pid $PID -var outfile print.txt"
  START=$(date -u +%Y-%m-%dT%H:%M:%SZ)
  LOAD=$(cut -d' ' -f1-3 /proc/loadavg)
  # shellcheck disable=SC2086
  (cd "$HERE" && nice -n "$NICE" liggghts -in in.penetration $VARS -var lawfile "in.law_$LAW" \
      -var datafile "$WORK/bed.data" -var pid "$PID" -var outfile "$WORK/print.txt" \
      -log "$WORK/log.liggghts" -echo none -screen none) || { tail -5 "$WORK/log.liggghts"; exit 1; }
  {
    echo "sphere-bed penetration, variant $V (reference/sphere_bed/README.md)"
    echo "code: LIGGGHTS-PUBLIC $(dpkg-query -W -f='${Version}' liggghts) (Debian package liggghts), serial, 1 process"
    echo "command: $CMD"
    echo "law: in.law_$LAW"
    echo "variant: $(python3 -c "import json;print(json.load(open('$BED/scene.json'))['variants']['$V'])")"
    echo "bed: bed_quick.csv, $((PID - 1)) spheres, velocities set to zero; walls of the bed material"
    echo "projectile: atom $PID, mass $MASS kg, start centre z0 = $Z0 m (= max(z+r) + gap + radius)"
    echo "date: $START"
    echo "machine: $(nproc) cores, $CPU; load average at start $LOAD (shared machine)"
    echo "particles: $PID"
  } > "$WORK/prov.txt"
  python3 "$HERE/post.py" "$V" "$WORK/print.txt" "$WORK/log.liggghts" "$MASS" "$Z0" "$WORK/prov.txt" "$OUT_DIR/$V.csv"
  grep -v -E '^\s*$' "$WORK/log.liggghts" | grep -v -E '^Histogram' > "$OUT_DIR/$V.log"
  rm -rf "$WORK"
done
