#!/usr/bin/env python3
"""Loose, overlap-free starting lattice for the bed, written as a LIGGGHTS data file.

Layers of a square lattice (spacing s), every other layer shifted by s/2 in x and y,
layer pitch s/sqrt(2) plus a small margin, so that no two spheres of radius
<= s/2 touch. Radii are uniform in [radius_min, radius_max]; each centre is moved
by a random offset small enough to keep every pair apart. Seeded (scene.json).
Usage: make_initial.py OUT.data
"""
import math
import random
import sys

from derived import load_scene


def main(out_path):
    sc = load_scene()
    bed = sc["bed"]
    rng = random.Random(bed["seed"])
    s = bed["lattice_spacing"]
    rmax = bed["radius_max"]
    if s < 2 * rmax:
        raise SystemExit("lattice spacing smaller than the largest diameter")
    pitch = s / math.sqrt(2.0) + 0.02 * s
    lx, ly = bed["box_x"], bed["box_y"]
    spheres = []
    layer = 0
    while len(spheres) < bed["count"]:
        shift = 0.5 * s * (layer % 2)
        z = bed["floor_z"] + 0.5 * s + layer * pitch
        x = 0.5 * s + shift
        while x + 0.5 * s <= lx + 1e-12 and len(spheres) < bed["count"]:
            y = 0.5 * s + shift
            while y + 0.5 * s <= ly + 1e-12 and len(spheres) < bed["count"]:
                r = rng.uniform(bed["radius_min"], bed["radius_max"])
                room = (0.5 * s - r) / math.sqrt(3.0)
                spheres.append((x + rng.uniform(-room, room), y + rng.uniform(-room, room),
                                z + rng.uniform(-room, room), r))
                y += s
            x += s
        layer += 1
    dens = sc["materials"]["bed"]["density"]
    ztop = max(p[2] for p in spheres) + s
    with open(out_path, "w") as f:
        f.write("sphere bed starting lattice (make_initial.py, seed %d)\n\n" % bed["seed"])
        f.write("%d atoms\n2 atom types\n\n" % len(spheres))
        f.write("0 %r xlo xhi\n0 %r ylo yhi\n%r %r zlo zhi\n\nAtoms\n\n" % (lx, ly, bed["floor_z"] - 0.05, ztop + 0.1))
        for i, (x, y, z, r) in enumerate(spheres, start=1):
            f.write("%d 1 %.17g %.17g %.17g %.17g %.17g\n" % (i, 2 * r, dens, x, y, z))
    print("wrote %d spheres in %d layers, top centre z = %.4f m" % (len(spheres), layer, ztop - s))


if __name__ == "__main__":
    main(sys.argv[1])
