#!/usr/bin/env python3
"""Turn the LIGGGHTS dump of the settled bed into bed_quick.csv with a provenance header.

Usage: dump_to_csv.py DUMP LOG OUT.csv PROVENANCE_TEXT_FILE
Keeps every number as LIGGGHTS wrote it (17 significant digits); only reorders columns.
"""
import sys


def main(dump, log, out, prov):
    with open(dump) as f:
        lines = f.read().splitlines()
    i = lines.index(next(l for l in lines if l.startswith("ITEM: ATOMS")))
    cols = lines[i].split()[2:]
    rows = [dict(zip(cols, l.split())) for l in lines[i + 1:] if l.strip()]
    rows.sort(key=lambda r: int(r["id"]))
    key_lines = []
    with open(log) as f:
        for l in f:
            w = l.split()
            if l.startswith(("LIGGGHTS (", "Loop time")) or (w and (w[0] == "Step" or w[0].isdigit())):
                key_lines.append(l.rstrip())
    with open(prov) as f:
        header = [l.rstrip("\n") for l in f]
    with open(out, "w") as f:
        for l in header + ["log key lines:"] + ["  " + k for k in key_lines]:
            f.write("# " + l + "\n")
        f.write("id,x,y,z,radius,vx,vy,vz\n")
        for r in rows:
            f.write(",".join(r[c] for c in ("id", "x", "y", "z", "radius", "vx", "vy", "vz")) + "\n")
    print("wrote %d spheres to %s" % (len(rows), out))


if __name__ == "__main__":
    main(*sys.argv[1:5])
