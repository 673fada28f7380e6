"""The elastic impact of two polyhedra (scenes/two_polyhedra_elastic.toml) stepped from Python, with the
energy trace: kinetic, elastic potential and their sum, sampled every few steps, and the relative drift
of the total printed at the end. With matplotlib installed, the trace is plotted to energy.png.

    python python/examples/elastic_impact_energy.py [SCENE]
"""

import pathlib
import sys

import numpy as np

import polydem

REPO = pathlib.Path(__file__).resolve().parents[2]

scene = sys.argv[1] if len(sys.argv) > 1 else REPO / "scenes/two_polyhedra_elastic.toml"
sim = polydem.Simulation.from_toml(scene)
trace = []


def sample(s):
    e = s.energy()
    kinetic = e["translational_kinetic"] + e["rotational_kinetic"]
    trace.append((s.time, kinetic, e["elastic_potential"], e["mechanical"]))


sample(sim)
sim.run(every=5 * sim.dt, callback=sample)
t, kinetic, elastic, total = np.array(trace).T
drift = np.abs(total - total[0]).max() / total[0]
print(f"{len(t)} samples over {t[-1]:.4g} s: largest |E - E0| / E0 = {drift:.2e}; "
      f"peak elastic energy {elastic.max() / total[0]:.3f} of E0")
try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib is not installed: no plot")
else:
    for values, label in ((kinetic, "kinetic"), (elastic, "elastic potential"), (total, "total")):
        plt.plot(t * 1e3, values, label=label)
    plt.xlabel("t (ms)")
    plt.ylabel("energy (J)")
    plt.legend()
    plt.savefig("energy.png", dpi=120)
    print("plotted to energy.png")
