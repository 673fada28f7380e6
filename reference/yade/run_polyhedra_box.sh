#!/bin/sh
# Run the polyhedra-in-a-box benchmark in YADE (one thread) and write polyhedra_box.csv and
# polyhedra_box.log into $OUT_DIR (default: out/ next to this script, the recorded run).
# Usage: sh run_polyhedra_box.sh. Installs yade if missing. The scene is ../polyhedra_box/scene.toml.
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
OUT_DIR=${OUT_DIR:-$HERE/out}
if ! command -v yade >/dev/null 2>&1; then
  apt-get install -y yade
fi
mkdir -p "$OUT_DIR"
LOG=$(mktemp)
CMD="yade -j1 -n -x polyhedra_box.py"
(cd "$HERE" && OUT="$OUT_DIR/polyhedra_box.csv" CMD="$CMD" SCRIPT="$HERE/polyhedra_box.py" nice -n 10 $CMD) > "$LOG" 2>&1 \
  || { cat "$LOG"; exit 1; }
# YADE's polyhedron intersection repeats one warning millions of times (hundreds of MB): the log keeps
# every other line and each distinct warning once, with the number of times it was printed.
grep -v -E 'TCP python prompt|XMLRPC info provider' "$LOG" \
  | awk '/WARNING/ { n[$0]++; if (n[$0] == 1) order[++k] = $0; next } { print }
         END { for (i = 1; i <= k; i++) printf "%s  [printed %d times]\n", order[i], n[order[i]] }' \
  > "$OUT_DIR/polyhedra_box.log"
tail -1 "$OUT_DIR/polyhedra_box.log"
rm -f "$LOG"
