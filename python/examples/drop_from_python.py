"""A scene built in Python: spheres on a grid dropped into an open box, run with a progress line and the
outputs of `polydem run` (CSV series, VTK frames for ParaView), then the contact list read as arrays.

    python python/examples/drop_from_python.py [OUT_DIR]
"""

import sys

import numpy as np

import polydem

n_side, radius = 6, 0.01
grid = np.arange(n_side) * 2.5 * radius
x, y, z = np.meshgrid(grid, grid, grid + 3 * radius, indexing="ij")
centres = np.column_stack([x.ravel(), y.ravel(), z.ravel()]) - [grid[-1] / 2, grid[-1] / 2, 0.0]
rng = np.random.default_rng(1)

scene = {
    "simulation": {"gravity": [0.0, 0.0, -9.81], "end_time": 0.3, "output_interval": 0.01,
                   "steps_per_contact": 40},
    "material": [{"name": "glass", "density": 2500.0}],
    "interaction": [{"materials": ["glass", "glass"], "law": "linear", "normal_stiffness": 2.0e4,
                     "restitution": 0.5, "tangential_stiffness": 1.0e4, "friction": 0.4}],
    "shape": [{"name": "ball", "kind": "sphere", "radius": radius}],
    "body": polydem.bodies("ball", count=len(centres), shape="ball", material="glass", position=centres,
                           velocity=rng.normal(0.0, 0.05, size=(len(centres), 3))),
    "box": [{"name": "bin", "material": "glass", "min": [-0.1, -0.1, 0.0], "max": [0.1, 0.1, 0.5],
             "open": ["z+"]}],
}


def progress(step, last):
    print(f"\rstep {step} of {last}", end="", file=sys.stderr, flush=True)


sim = polydem.Simulation(polydem.Scene.from_dict(scene, path="drop_from_python"))
out = sys.argv[1] if len(sys.argv) > 1 else "out/drop_from_python"
sim.run(out=out, vtk_interval=0.02, progress=progress)
print(file=sys.stderr)
contacts = sim.contacts()
normal_force = np.einsum("ij,ij->i", contacts["force"], contacts["normal"])
print(f"t = {sim.time:.3f} s: {len(normal_force)} contacts ({contacts['wall'].sum()} with walls), "
      f"mean normal force {normal_force.mean():.3e} N; outputs in {out}")
