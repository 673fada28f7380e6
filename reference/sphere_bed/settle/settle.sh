#!/bin/sh
# Generate and settle the bed once with LIGGGHTS, write ../bed_quick.csv.
# Usage: sh settle.sh   (from any directory; installs liggghts if missing)
set -eu
HERE=$(cd "$(dirname "$0")" && pwd)
BED=$(dirname "$HERE")
command -v liggghts >/dev/null 2>&1 || apt-get install -y liggghts
WORK=$(mktemp -d)
python3 "$BED/make_initial.py" "$WORK/init.data"
DT=$(python3 -c "import json;print(json.load(open('$BED/scene.json'))['settle']['dt'])")
NS=$(python3 -c "import json;print(json.load(open('$BED/scene.json'))['settle']['steps'])")
VARS=$(python3 "$BED/derived.py" --liggghts-vars a_hertz_5ms | sed -e 's/-var dt [^ ]*//' -e 's/-var nsteps [^ ]*//')
CMD="liggghts -in settle/in.settle $VARS -var dt $DT -var nsteps $NS -var datafile init.data -var dumpfile settled.dump"
START=$(date -u +%Y-%m-%dT%H:%M:%SZ)
# shellcheck disable=SC2086
(cd "$WORK" && nice -n 10 liggghts -in "$HERE/in.settle" $VARS -var dt "$DT" -var nsteps "$NS" \
    -var datafile init.data -var dumpfile settled.dump -log settle.log -echo none -screen none)
{
  echo "bed_quick.csv: settled sphere bed of the sphere-bed penetration scene (reference/sphere_bed/README.md)"
  echo "code: LIGGGHTS-PUBLIC $(dpkg-query -W -f='${Version}' liggghts 2>/dev/null) (Debian package liggghts), serial, 1 process"
  echo "command: $CMD"
  echo "generator: make_initial.py (seed from scene.json) -> LIGGGHTS settle, Hertz-Mindlin bed material, dt=$DT s, $NS steps"
  echo "scene: $(tr -d '\n' < "$BED/scene.json" | tr -s ' ')"
  echo "date: $START"
  echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
  echo "units: SI (m, m/s); velocities are the final LIGGGHTS velocities, importers set them to zero"
} > "$WORK/prov.txt"
python3 "$HERE/dump_to_csv.py" "$WORK/settled.dump" "$WORK/settle.log" "$BED/bed_quick.csv" "$WORK/prov.txt"
grep -E "^ +[0-9]+ +3000|Loop time" "$WORK/settle.log" | tail -4
rm -rf "$WORK"
