#!/bin/sh
# Run the sphere-bed penetration variants in YADE (one thread) and write out/<variant>.csv
# and out/<variant>.log. Usage: sh run.sh [variant ...] (default: every variant of
# ../sphere_bed/scene.json). Installs yade if missing. Environment: OUT_DIR (default: out/ here)
# receives the outputs; NICE (default 10) is the niceness of the run (the validation suite's full profile
# re-runs with OUT_DIR under its own output and NICE=0, the priority of its polydem run).
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
BED="$HERE/../sphere_bed"
if ! command -v yade >/dev/null 2>&1; then
  apt-get install -y yade
fi
VARIANTS=${*:-$(python3 -c "import json;print(' '.join(json.load(open('$BED/scene.json'))['variants']))")}
OUT_DIR=${OUT_DIR:-$HERE/out}
NICE=${NICE:-10}
mkdir -p "$OUT_DIR"
for V in $VARIANTS; do
  LOG=$(mktemp)
  CMD="VARIANT=$V yade -j1 -n -x penetration.py"
  (cd "$HERE" && VARIANT="$V" OUT="$OUT_DIR/$V.csv" CMD="$CMD" SCRIPT="$HERE/penetration.py" \
      nice -n "$NICE" yade -j1 -n -x penetration.py) > "$LOG" 2>&1 || { cat "$LOG"; exit 1; }
  grep -v -E 'TCP python prompt|XMLRPC info provider' "$LOG" > "$OUT_DIR/$V.log"
  tail -1 "$OUT_DIR/$V.log"
  rm -f "$LOG"
done
