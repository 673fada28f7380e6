#!/bin/sh
# Run the sphere-bed penetration variants in YADE (one thread) and write out/<variant>.csv
# and out/<variant>.log. Usage: sh run.sh [variant ...] (default: every variant of
# ../sphere_bed/scene.json). Installs yade if missing.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
BED="$HERE/../sphere_bed"
if ! command -v yade >/dev/null 2>&1; then
  apt-get install -y yade
fi
VARIANTS=${*:-$(python3 -c "import json;print(' '.join(json.load(open('$BED/scene.json'))['variants']))")}
mkdir -p "$HERE/out"
for V in $VARIANTS; do
  LOG=$(mktemp)
  CMD="VARIANT=$V yade -j1 -n -x penetration.py"
  (cd "$HERE" && VARIANT="$V" OUT="$HERE/out/$V.csv" CMD="$CMD" SCRIPT="$HERE/penetration.py" \
      nice -n 10 yade -j1 -n -x penetration.py) > "$LOG" 2>&1 || { cat "$LOG"; exit 1; }
  grep -v -E 'TCP python prompt|XMLRPC info provider' "$LOG" > "$HERE/out/$V.log"
  tail -1 "$HERE/out/$V.log"
  rm -f "$LOG"
done
