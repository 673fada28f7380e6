#!/usr/bin/env python3
"""LIGGGHTS data file: the bed of bed_quick.csv (type 1, velocities zero) plus the projectile
(type 2, last atom). Prints 'pid z0 mass' of the projectile.

Usage: make_data.py VARIANT OUT.data
"""
import csv
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
BED_DIR = os.path.join(HERE, "..", "sphere_bed")
sys.path.insert(0, BED_DIR)
import derived  # noqa: E402


def main(variant, out):
    sc = derived.load_scene()
    bed = sc["bed"]
    proj = sc["projectile"]
    rho_bed = sc["materials"]["bed"]["density"]
    rho_p = sc["materials"][proj["material"]]["density"]
    with open(os.path.join(BED_DIR, "bed_quick.csv")) as f:
        rows = list(csv.DictReader(l for l in f if not l.startswith("#")))
    ztop = max(float(r["z"]) + float(r["radius"]) for r in rows)
    z0 = ztop + proj["gap"] + proj["radius"]
    pid = len(rows) + 1
    margin = 0.001
    with open(out, "w") as f:
        f.write("sphere bed + projectile for variant %s (make_data.py)\n\n" % variant)
        f.write("%d atoms\n2 atom types\n\n" % pid)
        f.write("%r %r xlo xhi\n%r %r ylo yhi\n%r %r zlo zhi\n\nAtoms\n\n" % (
            -margin, bed["box_x"] + margin, -margin, bed["box_y"] + margin, bed["floor_z"] - 0.2, 0.3))
        for i, r in enumerate(rows, start=1):
            f.write("%d 1 %.17g %r %s %s %s\n" % (i, 2 * float(r["radius"]), rho_bed, r["x"], r["y"], r["z"]))
        f.write("%d 2 %.17g %r %.17g %.17g %.17g\n" % (pid, 2 * proj["radius"], rho_p,
                                                      0.5 * bed["box_x"], 0.5 * bed["box_y"], z0))
    m = 4.0 / 3.0 * math.pi * proj["radius"] ** 3 * rho_p
    print(pid, repr(z0), repr(m))


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
