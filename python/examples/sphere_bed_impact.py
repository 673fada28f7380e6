"""Sphere bed a (3000 spheres, a steel sphere struck into them at 5 m/s) scripted from Python: the
projectile's depth sampled every output interval, printed, and plotted with matplotlib when installed.

    python python/examples/sphere_bed_impact.py [END_TIME]
"""

import pathlib
import sys

import numpy as np

import polydem

REPO = pathlib.Path(__file__).resolve().parents[2]

sim = polydem.Simulation.from_toml(REPO / "scenes/sphere_bed_a_hertz_5ms.toml")
end = float(sys.argv[1]) if len(sys.argv) > 1 else 0.01
projectile = sim.names.index("projectile")
z0 = sim.positions()[projectile, 2]
samples = []
sim.run(until=end, every=20 * sim.dt,
        callback=lambda s: samples.append((s.time, z0 - s.positions()[projectile, 2], s.velocities()[projectile, 2])))
t, depth, vz = np.array(samples).T
print(f"t = {t[-1] * 1e3:.2f} ms: depth {depth[-1] * 1e3:.3f} mm, v_z {vz[-1]:.3f} m/s "
      f"({len(t)} samples, {sim.num_bodies} bodies)")
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no plot")
else:
    plt.plot(t * 1e3, depth * 1e3)
    plt.xlabel("t (ms)")
    plt.ylabel("depth z0 - z (mm)")
    plt.savefig("sphere_bed_depth.png", dpi=120)
    print("plotted to sphere_bed_depth.png")
