#!/usr/bin/env python3
"""Derived contact parameters of the sphere-bed scene (standard library only).

Everything here is computed from scene.json; nothing is typed in. Used by the
YADE script (imported), by the LIGGGHTS run script (`--liggghts-vars VARIANT`)
and by the README (`--table`).
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def load_scene(path=None):
    with open(path or os.path.join(HERE, "scene.json")) as f:
        return json.load(f)


def sphere_mass(radius, density):
    return 4.0 / 3.0 * math.pi * radius ** 3 * density


def effective_young(m1, m2):
    """E* = 1 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2)."""
    return 1.0 / ((1 - m1["poisson"] ** 2) / m1["young"] + (1 - m2["poisson"] ** 2) / m2["young"])


def effective_shear(m1, m2):
    """G* = 1 / ((2 - nu1)/G1 + (2 - nu2)/G2), G = E / (2 (1 + nu))."""
    g1 = m1["young"] / (2 * (1 + m1["poisson"]))
    g2 = m2["young"] / (2 * (1 + m2["poisson"]))
    return 1.0 / ((2 - m1["poisson"]) / g1 + (2 - m2["poisson"]) / g2)


def log_beta(e):
    """Damping ratio of a linear spring-dashpot with restitution e: |ln e| / sqrt(ln^2 e + pi^2)."""
    le = math.log(e)
    return -le / math.sqrt(le * le + math.pi ** 2)


def hertz_damping_ratio(e):
    """Ratio b in c_n = 2 b sqrt(m* k_tangent), k_tangent = 2 E* sqrt(R* delta).

    This is the LIGGGHTS 3.8 'model hertz' damping (b = sqrt(5/6) * log_beta(e));
    YADE's Ip2_FrictMat_FrictMat_MindlinPhys gets the same number through its
    betan/betas attributes so that both codes run the same law.
    """
    return math.sqrt(5.0 / 6.0) * log_beta(e)


def hertz_restitution(b, steps=200000):
    """Restitution actually produced by the Hertz law with damping ratio b.

    Non-dimensional head-on impact (m* = 1, k = 1, impact speed 1; the result does not
    depend on the speed): x'' = -x^1.5 - 2 b sqrt(1.5) x^0.25 x', force clamped at zero
    (no attraction, as in both codes). RK4; the contact ends when the force vanishes.
    """
    def acc(x, v):
        if x <= 0.0:
            return 0.0
        f = x ** 1.5 + 2.0 * b * math.sqrt(1.5) * x ** 0.25 * v
        return -max(f, 0.0)

    x, v = 0.0, 1.0
    h = 4.0 / steps
    for _ in range(steps):
        k1x, k1v = v, acc(x, v)
        k2x, k2v = v + 0.5 * h * k1v, acc(x + 0.5 * h * k1x, v + 0.5 * h * k1v)
        k3x, k3v = v + 0.5 * h * k2v, acc(x + 0.5 * h * k2x, v + 0.5 * h * k2v)
        k4x, k4v = v + h * k3v, acc(x + h * k3x, v + h * k3v)
        x += h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x)
        v += h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v)
        if v < 0.0 and (x <= 0.0 or acc(x, v) == 0.0):
            return -v
    raise RuntimeError("contact did not end")


def rayleigh_time(radius, mat):
    g = mat["young"] / (2 * (1 + mat["poisson"]))
    return math.pi * radius * math.sqrt(mat["density"] / g) / (0.1631 * mat["poisson"] + 0.8766)


def hertz_impact(m_eff, r_eff, e_eff, v):
    """Elastic Hertz impact: (max overlap, contact duration) at normal speed v."""
    delta = (15.0 * m_eff * v * v / (16.0 * e_eff * math.sqrt(r_eff))) ** 0.4
    t = 2.868265 * (m_eff * m_eff / (r_eff * e_eff * e_eff * v)) ** 0.2
    return delta, t


def pair_state(scene):
    """Mean bed sphere, projectile, and the effective quantities of their pairs."""
    bed = scene["bed"]
    mats = scene["materials"]
    r_mean = 0.5 * (bed["radius_min"] + bed["radius_max"])
    m_bed = sphere_mass(r_mean, mats["bed"]["density"])
    proj = scene["projectile"]
    m_proj = sphere_mass(proj["radius"], mats[proj["material"]]["density"])
    return {
        "r_mean": r_mean,
        "m_bed_mean": m_bed,
        "m_proj": m_proj,
        "bb": {"m": m_bed / 2.0, "r": r_mean / 2.0,
               "E": effective_young(mats["bed"], mats["bed"]),
               "G": effective_shear(mats["bed"], mats["bed"])},
        "bp": {"m": m_bed * m_proj / (m_bed + m_proj), "r": r_mean * proj["radius"] / (r_mean + proj["radius"]),
               "E": effective_young(mats["bed"], mats[proj["material"]]),
               "G": effective_shear(mats["bed"], mats[proj["material"]])},
    }


def linear_parameters(scene):
    """Linear spring-dashpot variant.

    k_n: one value for every contact, the secant stiffness of the Hertz law at the
    largest overlap of a head-on impact of two mean bed spheres at the reference
    speed (k = 16/15 sqrt(R*) E* (15 m* v^2 / (16 sqrt(R*) E*))^(1/5)).
    k_t = kt_over_kn * k_n. c_n per pair type from the restitution of that pair
    type, exact for the reference masses: c = 2 log_beta(e) sqrt(m* k_n).
    Tangential damping off.
    """
    st = pair_state(scene)
    bb = st["bb"]
    v = scene["linear"]["reference_speed"]
    kn = 16.0 / 15.0 * math.sqrt(bb["r"]) * bb["E"] * (
        15.0 * bb["m"] * v * v / (16.0 * math.sqrt(bb["r"]) * bb["E"])) ** 0.2
    kt = scene["linear"]["kt_over_kn"] * kn
    e_bb = scene["pairs"]["bed_bed"]["restitution"]
    e_bp = scene["pairs"]["bed_steel"]["restitution"]
    cn_bb = 2.0 * log_beta(e_bb) * math.sqrt(bb["m"] * kn)
    cn_bp = 2.0 * log_beta(e_bp) * math.sqrt(st["bp"]["m"] * kn)
    # YADE's ViscElMat combines per-material values in series (1/k = 1/k1 + 1/k2):
    # the bed material carries 2 k_n and 2 c_bb, the steel material what makes the
    # series value equal c_bp.
    cn_bed_mat = 2.0 * cn_bb
    if cn_bp >= cn_bed_mat:
        raise ValueError("c_bp >= 2 c_bb: cannot be represented by YADE's series combination")
    cn_steel_mat = cn_bp * cn_bed_mat / (cn_bed_mat - cn_bp)
    return {"kn": kn, "kt": kt, "cn_bb": cn_bb, "cn_bp": cn_bp,
            "yade_kn_mat": 2.0 * kn, "yade_ks_mat": 2.0 * kt,
            "yade_cn_bed_mat": cn_bed_mat, "yade_cn_steel_mat": cn_steel_mat}


def table(scene):
    st = pair_state(scene)
    bed = scene["bed"]
    mats = scene["materials"]
    lin = linear_parameters(scene)
    rows = []
    tr = rayleigh_time(bed["radius_min"], mats["bed"])
    rows.append(("Rayleigh time of the smallest bed sphere T_R", tr, "s"))
    for name, v in scene["variants"].items():
        rows.append((f"{name}: dt / T_R", v["dt"] / tr, "-"))
    for label, key in (("bed-bed (mean spheres)", "bb"), ("bed-projectile (mean sphere)", "bp")):
        p = st[key]
        for speed in sorted({v["speed"] for v in scene["variants"].values()}):
            d, t = hertz_impact(p["m"], p["r"], p["E"], speed)
            rows.append((f"Hertz {label} at {speed:g} m/s: max overlap / R*", d / p["r"], "-"))
            rows.append((f"Hertz {label} at {speed:g} m/s: contact time", t, "s"))
    rows.append(("Hertz damping ratio b (bed-bed, e=%.2f)" % scene["pairs"]["bed_bed"]["restitution"],
                 hertz_damping_ratio(scene["pairs"]["bed_bed"]["restitution"]), "-"))
    rows.append(("Hertz damping ratio b (bed-steel, e=%.2f)" % scene["pairs"]["bed_steel"]["restitution"],
                 hertz_damping_ratio(scene["pairs"]["bed_steel"]["restitution"]), "-"))
    for key in ("bed_bed", "bed_steel"):
        e = scene["pairs"][key]["restitution"]
        rows.append(("restitution actually produced by the Hertz law for input e=%.2f" % e,
                     hertz_restitution(hertz_damping_ratio(e)), "-"))
    rows.append(("linear k_n (all pairs)", lin["kn"], "N/m"))
    rows.append(("linear k_t (all pairs)", lin["kt"], "N/m"))
    rows.append(("linear c_n bed-bed and bed-wall", lin["cn_bb"], "N s/m"))
    rows.append(("linear c_n bed-projectile and projectile-wall", lin["cn_bp"], "N s/m"))
    m_small = sphere_mass(bed["radius_min"], mats["bed"]["density"]) / 2.0
    rows.append(("linear contact time, two smallest bed spheres", math.pi / math.sqrt(lin["kn"] / m_small), "s"))
    rows.append(("mean bed sphere mass", st["m_bed_mean"], "kg"))
    rows.append(("projectile mass", st["m_proj"], "kg"))
    return rows


def liggghts_vars(scene, variant):
    v = scene["variants"][variant]
    mats = scene["materials"]
    pr = scene["pairs"]
    lin = linear_parameters(scene)
    out = {
        "law": v["law"], "dt": v["dt"], "nsteps": v["steps"], "every": v["sample_every"],
        "speed": v["speed"], "floor": 1 if v["floor"] else 0,
        "Ebed": mats["bed"]["young"], "Esteel": mats["steel"]["young"],
        "nubed": mats["bed"]["poisson"], "nusteel": mats["steel"]["poisson"],
        "mubb": pr["bed_bed"]["friction"], "mubp": pr["bed_steel"]["friction"],
        "ebb": pr["bed_bed"]["restitution"], "ebp": pr["bed_steel"]["restitution"],
        "kn": lin["kn"], "kt": lin["kt"], "cnbb": lin["cn_bb"], "cnbp": lin["cn_bp"],
        "boxx": scene["bed"]["box_x"], "boxy": scene["bed"]["box_y"], "g": scene["gravity"],
    }
    return " ".join(f"-var {k} {val!r}" if not isinstance(val, str) else f"-var {k} {val}"
                    for k, val in out.items())


if __name__ == "__main__":
    sc = load_scene()
    if len(sys.argv) == 3 and sys.argv[1] == "--liggghts-vars":
        print(liggghts_vars(sc, sys.argv[2]))
    else:
        print("| quantity | value | unit |\n|---|---|---|")
        for name, val, unit in table(sc):
            print(f"| {name} | {val:.4g} | {unit} |")
