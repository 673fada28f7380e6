# The polyhedra-in-a-box timing benchmark in YADE (run by run_polyhedra_box.sh: yade -j1 -n -x polyhedra_box.py).
# Reads the polydem scene file (../polyhedra_box/scene.toml, written by make_scene.py there) so that both codes start from the
# same vertices, walls, time step and end time. YADE's own polyhedra law (Law2_PolyhedraGeom_PolyhedraPhys_
# Volumetric: normal force proportional to the overlap volume) stands in for polydem's Minkowski-overlap
# law; the stiffness is matched as the README explains. Environment: OUT (CSV path), STEPS (optional: run
# only this many steps, for a quick timing), CMD (command line, for the provenance header).
import csv
import datetime
import math
import os
import platform
import time
import tomllib

from yade import polyhedra_utils

HERE = os.path.dirname(os.path.abspath(os.environ.get("SCRIPT", "polyhedra_box.py")))
OUT = os.environ["OUT"]
with open(os.path.join(HERE, "..", "polyhedra_box", "scene.toml"), "rb") as f:
    scene = tomllib.load(f)

sim = scene["simulation"]
mat = scene["material"][0]
law = scene["interaction"][0]
assert law["law"] == "linear" and law["restitution"] == 1.0, "the benchmark matches an elastic linear law"
shapes = {s["name"]: s["points"] for s in scene["shape"]}

# Stiffness match (README): a volumetric stiffness k_v = k_n / A_ref gives the same force as polydem's
# linear law for a face-to-face overlap of area A_ref = r_eq^2, r_eq the mean volume-equivalent radius.
# Y = 2 k_v because YADE combines the two materials in series; ks = Y*poisson/2 reproduces k_t.
volumes = []
bounding_radii = []
for b in scene["body"]:
    shp = Polyhedra(v=[Vector3(*p) for p in shapes[b["shape"]]])
    volumes.append(shp.GetVolume())
    c = shp.GetCentroid()
    bounding_radii.append(max((Vector3(*p) - c).norm() for p in shapes[b["shape"]]))
# The same Verlet distance as polydem's default skin: 0.2 x the smallest bounding radius.
verlet = 0.2 * min(bounding_radii)
r_eq = sum((3 * v / (4 * math.pi)) ** (1 / 3) for v in volumes) / len(volumes)
a_ref = r_eq ** 2
k_v = law["normal_stiffness"] / a_ref
young = 2 * k_v
poisson = law["tangential_stiffness"] / k_v

rock = O.materials.append(PolyhedraMat(young=young, poisson=poisson, density=mat["density"],
                                       frictionAngle=math.atan(law["friction"]), label="rock"))
for b in scene["body"]:
    O.bodies.append(polyhedra_utils.polyhedra(O.materials[rock], v=[Vector3(*p) for p in shapes[b["shape"]]]))
n_bodies = len(O.bodies)
for w in scene["wall"]:
    normal = w["normal"]
    axis = max(range(3), key=lambda i: abs(normal[i]))
    assert abs(abs(normal[axis]) - 1) < 1e-12, "walls must be axis-aligned for yade's utils.wall"
    sense = 1 if normal[axis] > 0 else -1
    O.bodies.append(utils.wall(w["point"][axis], axis=axis, sense=sense, material=O.materials[rock]))

O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Polyhedra_Aabb(), Bo1_Wall_Aabb()], verletDist=verlet),
    InteractionLoop(
        [Ig2_Polyhedra_Polyhedra_PolyhedraGeom(), Ig2_Wall_Polyhedra_PolyhedraGeom()],
        [Ip2_PolyhedraMat_PolyhedraMat_PolyhedraPhys()],
        [Law2_PolyhedraGeom_PolyhedraPhys_Volumetric()],
    ),
    NewtonIntegrator(damping=0.0, gravity=Vector3(*sim["gravity"])),
]
O.dt = sim["time_step"]
steps = int(os.environ.get("STEPS", "0")) or int(round(sim["end_time"] / sim["time_step"]))
every = max(1, int(round(sim["output_interval"] / sim["time_step"])))

rows = []


def record():
    zs = [O.bodies[i].state.pos[2] for i in range(n_bodies)]
    ke = sum(0.5 * O.bodies[i].state.mass * O.bodies[i].state.vel.squaredNorm() for i in range(n_bodies))
    # Real interactions whose polyhedra overlap (YADE keeps interactions of AABB-overlapping pairs whose
    # shapes do not touch; polydem counts overlapping pairs only).
    contacts = sum(1 for i in O.interactions if i.isReal and i.geom.penetrationVolume > 0)
    real = sum(1 for i in O.interactions if i.isReal)
    rows.append((O.time, sum(zs) / n_bodies, min(zs), ke, contacts, real))


record()
# Wall time and the process's CPU time (on a shared machine the CPU time is the cost of the run; the wall
# time also holds the waits for a busy core). Recording the monitors is not part of either.
wall = 0.0
cpu = 0.0
done = 0
while done < steps:
    n = min(every, steps - done)
    w0, c0 = time.perf_counter(), time.process_time()
    O.run(n, True)
    wall += time.perf_counter() - w0
    cpu += time.process_time() - c0
    done += n
    record()

with open(OUT, "w", newline="") as f:
    f.write("# code: YADE %s (Debian package), single thread (-j1)\n" % version)
    f.write("# command: %s\n" % os.environ.get("CMD", "yade -j1 -n -x polyhedra_box.py"))
    f.write("# scene: reference/polyhedra_box/scene.toml, %d polyhedra, dt = %g s, %d steps\n" % (n_bodies, O.dt, steps))
    f.write("# law: Law2_PolyhedraGeom_PolyhedraPhys_Volumetric, young = %.6g, poisson = %.6g "
            "(k_v = %.6g N/m^3 = k_n / r_eq^2, r_eq = %.6g m), frictionAngle = atan(%g), NewtonIntegrator damping 0, verletDist %.6g m\n"
            % (young, poisson, k_v, r_eq, law["friction"], verlet))
    f.write("# date: %s, machine: %s, %s\n" % (datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                                              platform.node(), platform.processor() or platform.machine()))
    f.write("# wall time (s): %.3f, cpu time (s): %.3f, particle-steps per cpu second: %.4e\n"
            % (wall, cpu, n_bodies * steps / cpu))
    wr = csv.writer(f)
    wr.writerow(["t", "mean_z", "min_z", "kinetic_energy", "contacts", "real_interactions"])
    for r in rows:
        wr.writerow(["%.6g" % r[0], "%.9g" % r[1], "%.9g" % r[2], "%.9g" % r[3], r[4], r[5]])
print("YADE polyhedra_box: %d steps in %.2f s wall, %.2f s cpu, %.4e particle-steps per cpu second, mean z %.6g, contacts %d"
      % (steps, wall, cpu, n_bodies * steps / cpu, rows[-1][1], rows[-1][4]))
