#!/usr/bin/env python3
"""Turn LIGGGHTS' fix print file and log into out/<variant>.csv with a provenance header.

The contact force is the total force on the projectile minus its weight (LIGGGHTS' fix
gravity adds m g to f before fix print reads it). Numbers are rounded to 9 significant
digits (as in the YADE output); nothing else is changed.
Usage: post.py VARIANT PRINTFILE LOGFILE MASS Z0 PROVENANCE_FILE OUT.csv
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "sphere_bed"))
import derived  # noqa: E402


def main(variant, printfile, logfile, mass, z0, prov, out):
    sc = derived.load_scene()
    var = sc["variants"][variant]
    g = sc["gravity"]
    mass = float(mass)
    rows = []
    with open(printfile) as f:
        for l in f:
            w = l.split()
            if not w or not w[0][0].isdigit():
                continue
            rows.append(w)
    loop = None
    key = []
    with open(logfile) as f:
        for l in f:
            w = l.split()
            if l.startswith(("LIGGGHTS (", "Loop time", "WARNING", "ERROR")) or (w and (w[0] == "Step" or w[0].isdigit())):
                key.append(l.rstrip())
            if l.startswith("Loop time") and " steps with " in l:
                loop = l
    if loop is None:
        raise SystemExit("no 'Loop time' line in " + logfile)
    w = loop.split()
    wall = float(w[3])
    steps = int(w[8])
    with open(prov) as f:
        header = [l.rstrip("\n") for l in f]
    nparticles = int(header_value(header, "particles"))
    header += [
        "sampling: after every %d-th step (fix print); position, velocity and force at the end of the step (velocity Verlet)" % var["sample_every"],
        "force: resultant contact force on the projectile = LIGGGHTS total force - m g (m = %.9g kg)" % mass,
        "steps: %d" % steps,
        "wall_time_s: %.3f" % wall,
        "particle_steps_per_s: %.4g" % (nparticles * steps / wall),
        "z0: %s" % z0,
        "log key lines:",
    ] + ["  " + k for k in key]
    with open(out, "w") as f:
        for h in header:
            f.write("# " + h + "\n")
        f.write("t,step,x,y,z,vx,vy,vz,fx,fy,fz,contacts\n")
        f.write("0,0,%.9g,%.9g,%.9g,0,0,%.9g,0,0,0,0\n" % (0.5 * sc["bed"]["box_x"], 0.5 * sc["bed"]["box_y"], float(z0), -var["speed"]))
        for r in rows:
            t, st, x, y, z, vx, vy, vz, fx, fy, fz, nc = r
            f.write("%.9g,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d\n" % (
                float(t), int(st), float(x), float(y), float(z), float(vx), float(vy), float(vz),
                float(fx), float(fy), float(fz) + mass * g, round(float(nc))))
    print("LIGGGHTS %s: %d steps in %.2f s wall, %.4g particle-steps/s, final z %s vz %s" % (
        variant, steps, wall, nparticles * steps / wall, rows[-1][4], rows[-1][7]))


def header_value(header, key):
    for h in header:
        if h.startswith(key + ":"):
            return h.split(":", 1)[1].strip()
    raise SystemExit("missing %s in provenance" % key)


if __name__ == "__main__":
    main(*sys.argv[1:8])
