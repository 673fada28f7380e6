#!/usr/bin/env python3
"""Side-by-side table of the recorded YADE and LIGGGHTS sphere-bed penetration runs.

Reads ../yade/out/<variant>.csv and ../liggghts/out/<variant>.csv (standard library only)
and prints a Markdown table per variant. The YADE-LIGGGHTS spread printed here is the
yardstick for later agreement with polydem. Usage: compare.py [variant ...]
"""
import csv
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import derived  # noqa: E402

CODES = (("YADE", "yade"), ("LIGGGHTS", "liggghts"))


def read_run(path):
    meta = {}
    lines = []
    with open(path) as f:
        for l in f:
            if l.startswith("# "):
                k, sep, v = l[2:].partition(":")
                if sep and k and " " not in k.strip():
                    meta.setdefault(k.strip(), v.strip())
            elif not l.startswith("#"):
                lines.append(l)
    rows = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(lines)]
    return meta, rows


def metrics(meta, rows, v0):
    z0 = rows[0]["z"]
    last = rows[-1]
    fmag = [math.sqrt(r["fx"] ** 2 + r["fy"] ** 2 + r["fz"] ** 2) for r in rows]
    ipk = max(range(len(rows)), key=lambda i: fmag[i])
    touched = [r for r in rows if r["contacts"] > 0]
    t_first = touched[0]["t"] if touched else float("nan")
    slow = next((r["t"] for r in rows if math.sqrt(r["vx"] ** 2 + r["vy"] ** 2 + r["vz"] ** 2) < 0.1 * v0), float("nan"))
    after = [r for r in rows if r["t"] >= t_first] if touched else []
    impulse = 0.0
    for a, b in zip(rows, rows[1:]):
        impulse += 0.5 * (a["fz"] + b["fz"]) * (b["t"] - a["t"])
    return {
        "final depth z0-z(t_end) [mm]": 1e3 * (z0 - last["z"]),
        "max depth z0-min z [mm]": 1e3 * (z0 - min(r["z"] for r in rows)),
        "final vertical velocity [m/s]": last["vz"],
        "final lateral offset [mm]": 1e3 * math.hypot(last["x"] - rows[0]["x"], last["y"] - rows[0]["y"]),
        "peak contact force [N]": fmag[ipk],
        "time of peak force [ms]": 1e3 * rows[ipk]["t"],
        "first contact [ms]": 1e3 * t_first,
        "speed below 10% of v0 at [ms]": 1e3 * slow,
        "vertical contact impulse [N s]": impulse,
        "mean projectile contacts after impact": (sum(r["contacts"] for r in after) / len(after)) if after else float("nan"),
        "samples in contact after impact [%]": (100.0 * sum(1 for r in after if r["contacts"] > 0) / len(after)) if after else float("nan"),
        "steps": float(meta["steps"]),
        "wall time [s]": float(meta["wall_time_s"]),
        "particle-steps per second": float(meta["particle_steps_per_s"]),
    }


def trajectory_gap(ra, rb, d_mean):
    """Largest and RMS |z_YADE - z_LIGGGHTS| over samples at the same step, in mean diameters."""
    zb = {int(r["step"]): r["z"] for r in rb}
    diffs = [ra_i["z"] - zb[int(ra_i["step"])] for ra_i in ra if int(ra_i["step"]) in zb]
    if not diffs:
        return float("nan"), float("nan"), 0
    return (max(abs(d) for d in diffs) / d_mean, math.sqrt(sum(d * d for d in diffs) / len(diffs)) / d_mean, len(diffs))


def fmt(x):
    if isinstance(x, float) and math.isnan(x):
        return "n/a"
    if abs(x) >= 1e4 or (abs(x) < 1e-2 and x != 0):
        return "%.3e" % x
    return "%.4g" % x


def main(variants):
    sc = derived.load_scene()
    d_mean = sc["bed"]["radius_min"] + sc["bed"]["radius_max"]
    ref = os.path.join(HERE, "..")
    for v in variants or list(sc["variants"]):
        v0 = sc["variants"][v]["speed"]
        runs = {}
        for name, d in CODES:
            p = os.path.join(ref, d, "out", v + ".csv")
            if os.path.exists(p):
                runs[name] = read_run(p)
        print("### %s (v0 = %g m/s, law %s, dt = %g s, %d steps)\n" % (
            v, v0, sc["variants"][v]["law"], sc["variants"][v]["dt"], sc["variants"][v]["steps"]))
        if len(runs) < 2:
            print("missing output: have %s\n" % ", ".join(runs) or "none")
            continue
        m = {k: metrics(meta, rows, v0) for k, (meta, rows) in runs.items()}
        print("| quantity | YADE | LIGGGHTS | spread (abs(Y-L)/mean) |")
        print("|---|---|---|---|")
        for q in m["YADE"]:
            a, b = m["YADE"][q], m["LIGGGHTS"][q]
            mean = 0.5 * (abs(a) + abs(b))
            spread = abs(a - b) / mean if mean > 0 and not any(map(math.isnan, (a, b))) else float("nan")
            timing = q in ("steps", "wall time [s]", "particle-steps per second")
            sp = "n/a" if timing or math.isnan(spread) else "%.1f %%" % (100 * spread)
            print("| %s | %s | %s | %s |" % (q, fmt(a), fmt(b), sp))
        mx, rms, n = trajectory_gap(runs["YADE"][1], runs["LIGGGHTS"][1], d_mean)
        print("\nTrajectory gap z_YADE - z_LIGGGHTS over %d common samples: max %.4g, RMS %.4g mean bed diameters"
              " (mean diameter %.3g mm). Speed ratio LIGGGHTS/YADE (particle-steps per second): %.3g.\n" % (
                  n, mx, rms, 1e3 * d_mean,
                  m["LIGGGHTS"]["particle-steps per second"] / m["YADE"]["particle-steps per second"]))


if __name__ == "__main__":
    main(sys.argv[1:])
