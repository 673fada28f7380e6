# Sphere-bed penetration in YADE (run by run.sh: yade -j1 -n -x penetration.py).
# Scene, materials and variant from ../sphere_bed/scene.json; the bed state from
# ../sphere_bed/bed_quick.csv (positions and radii, velocities set to zero).
# Environment: VARIANT (key of scene.json "variants"), OUT (CSV path), CMD (command
# line, for the provenance header).
import csv
import math
import os
import platform
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(os.environ.get("SCRIPT", "penetration.py")))
BED_DIR = os.path.join(HERE, "..", "sphere_bed")
sys.path.insert(0, BED_DIR)
import derived  # noqa: E402

VARIANT = os.environ["VARIANT"]
OUT = os.environ["OUT"]
sc = derived.load_scene()
var = sc["variants"][VARIANT]
mats = sc["materials"]
pairs = sc["pairs"]
proj = sc["projectile"]
bed = sc["bed"]

# ---- materials and contact law -------------------------------------------------
if var["law"] == "hertz":
    bed_mat = O.materials.append(FrictMat(young=mats["bed"]["young"], poisson=mats["bed"]["poisson"],
                                          density=mats["bed"]["density"],
                                          frictionAngle=math.atan(pairs["bed_bed"]["friction"]), label="bed"))
    steel_mat = O.materials.append(FrictMat(young=mats["steel"]["young"], poisson=mats["steel"]["poisson"],
                                            density=mats["steel"]["density"],
                                            frictionAngle=math.atan(pairs["bed_steel"]["friction"]), label="steel"))
    b_bb = derived.hertz_damping_ratio(pairs["bed_bed"]["restitution"])
    b_bp = derived.hertz_damping_ratio(pairs["bed_steel"]["restitution"])
    table = ((bed_mat, bed_mat, b_bb), (bed_mat, steel_mat, b_bp), (steel_mat, steel_mat, b_bp))
    ip2 = Ip2_FrictMat_FrictMat_MindlinPhys(betan=MatchMaker(matches=table), betas=MatchMaker(matches=table))
    law2 = Law2_ScGeom_MindlinPhys_Mindlin()
    law_text = "Ip2_FrictMat_FrictMat_MindlinPhys(betan=betas=MatchMaker bed-bed %.6g, bed-steel %.6g) + Law2_ScGeom_MindlinPhys_Mindlin" % (b_bb, b_bp)
elif var["law"] == "linear":
    lin = derived.linear_parameters(sc)
    bed_mat = O.materials.append(ViscElMat(kn=lin["yade_kn_mat"], ks=lin["yade_ks_mat"], cn=lin["yade_cn_bed_mat"], cs=0.0,
                                           density=mats["bed"]["density"],
                                           frictionAngle=math.atan(pairs["bed_bed"]["friction"]), label="bed"))
    steel_mat = O.materials.append(ViscElMat(kn=lin["yade_kn_mat"], ks=lin["yade_ks_mat"], cn=lin["yade_cn_steel_mat"], cs=0.0,
                                             density=mats["steel"]["density"],
                                             frictionAngle=math.atan(pairs["bed_steel"]["friction"]), label="steel"))
    ip2 = Ip2_ViscElMat_ViscElMat_ViscElPhys()
    law2 = Law2_ScGeom_ViscElPhys_Basic()
    law_text = "ViscElMat (series-combined per material: pair kn=%.6g ks=%.6g cn_bb=%.6g cn_bp=%.6g cs=0) + Law2_ScGeom_ViscElPhys_Basic" % (
        lin["kn"], lin["kt"], lin["cn_bb"], lin["cn_bp"])
else:
    raise SystemExit("unknown law " + var["law"])

# ---- bodies ----------------------------------------------------------------------
with open(os.path.join(BED_DIR, "bed_quick.csv")) as f:
    rows = list(csv.DictReader(l for l in f if not l.startswith("#")))
ztop = 0.0
for r in rows:
    x, y, z, rad = (float(r[k]) for k in ("x", "y", "z", "radius"))
    O.bodies.append(sphere((x, y, z), rad, material=bed_mat))
    ztop = max(ztop, z + rad)
n_bed = len(rows)
walls = [utils.wall(0.0, axis=0, material=bed_mat), utils.wall(bed["box_x"], axis=0, material=bed_mat),
         utils.wall(0.0, axis=1, material=bed_mat), utils.wall(bed["box_y"], axis=1, material=bed_mat)]
if var["floor"]:
    walls.append(utils.wall(bed["floor_z"], axis=2, material=bed_mat))
O.bodies.append(walls)
z0 = ztop + proj["gap"] + proj["radius"]
pid = O.bodies.append(sphere((0.5 * bed["box_x"], 0.5 * bed["box_y"], z0), proj["radius"], material=steel_mat))
O.bodies[pid].state.vel = Vector3(0, 0, -var["speed"])
m_proj = O.bodies[pid].state.mass

# ---- engines ---------------------------------------------------------------------
samples = []


def sample():
    # runs after NewtonIntegrator: positions/velocities after this step, force of this step
    step = O.iter + 1
    if step % var["sample_every"]:
        return
    s = O.bodies[pid].state
    f = O.forces.f(pid)
    nc = sum(1 for i in O.bodies[pid].intrs() if i.isReal)
    samples.append((O.time + O.dt, step, s.pos[0], s.pos[1], s.pos[2], s.vel[0], s.vel[1], s.vel[2], f[0], f[1], f[2], nc))


O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()], [ip2], [law2]),
    NewtonIntegrator(damping=0.0, gravity=(0, 0, -sc["gravity"])),
    PyRunner(command="sample()", iterPeriod=1),
]
O.dt = var["dt"]
s0 = O.bodies[pid].state
samples.append((0.0, 0, s0.pos[0], s0.pos[1], s0.pos[2], s0.vel[0], s0.vel[1], s0.vel[2], 0.0, 0.0, 0.0, 0))
start = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
with open("/proc/loadavg") as f:
    loadavg = " ".join(f.read().split()[:3])
t0 = time.time()
O.run(var["steps"], True)
wall = time.time() - t0

# ---- output ----------------------------------------------------------------------
def dpkg_version(pkg):
    try:
        return subprocess.run(["dpkg-query", "-W", "-f=${Version}", pkg], capture_output=True, text=True).stdout
    except OSError:
        return "unknown"


cpu = "unknown"
with open("/proc/cpuinfo") as f:
    for l in f:
        if l.startswith("model name"):
            cpu = l.split(":", 1)[1].strip()
            break
header = [
    "sphere-bed penetration, variant %s (reference/sphere_bed/README.md)" % VARIANT,
    "code: YADE %s (Debian package yade %s), single thread (-j1)" % (version, dpkg_version("yade")),
    "command: %s" % os.environ.get("CMD", "yade -j1 -n -x penetration.py"),
    "law: %s" % law_text,
    "variant: %s" % {k: var[k] for k in sorted(var)},
    "bed: bed_quick.csv, %d spheres, velocities set to zero; walls of the bed material; floor=%s" % (n_bed, var["floor"]),
    "projectile: radius %g m, mass %.9g kg, start centre z0 = %.9g m (= max(z+r) + gap + radius), vz0 = %g m/s" % (
        proj["radius"], m_proj, z0, -var["speed"]),
    "date: %s" % start,
    "machine: %d cores, %s; python %s; load average at start %s (shared machine)" % (
        os.cpu_count(), cpu, platform.python_version(), loadavg),
    "sampling: after every %d-th step; position and force at the end of the step, velocity at the half step (YADE leapfrog)" % var["sample_every"],
    "force: resultant contact force on the projectile (gravity excluded)",
    "particles: %d" % (n_bed + 1),
    "steps: %d" % var["steps"],
    "wall_time_s: %.3f" % wall,
    "particle_steps_per_s: %.4g" % ((n_bed + 1) * var["steps"] / wall),
    "z0: %.12g" % z0,
]
with open(OUT, "w") as f:
    for h in header:
        f.write("# " + h + "\n")
    f.write("t,step,x,y,z,vx,vy,vz,fx,fy,fz,contacts\n")
    for s in samples:
        f.write("%.9g,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%d\n" % s)
print("YADE %s: %d steps in %.2f s wall, %.4g particle-steps/s, final z %.6g vz %.6g" % (
    VARIANT, var["steps"], wall, (n_bed + 1) * var["steps"] / wall, samples[-1][4], samples[-1][7]))
O.exitNoBacktrace() if hasattr(O, "exitNoBacktrace") else None
