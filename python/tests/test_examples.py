"""The examples in python/examples run as documented."""

import subprocess
import sys


def test_drop_from_python_runs_and_writes_its_outputs(repo, tmp_path):
    done = subprocess.run([sys.executable, str(repo / "python/examples/drop_from_python.py"), str(tmp_path)],
                          capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "contacts" in done.stdout and "step 7466 of 7466" in done.stderr, (done.stdout, done.stderr[-300:])
    for name in ("bodies.csv", "energy.csv", "walls.csv", "spheres.pvd", "walls.pvd"):
        assert (tmp_path / name).is_file(), f"{name} missing; the directory holds {sorted(p.name for p in tmp_path.iterdir())}"


def run_example(repo, tmp_path, name, *args):
    done = subprocess.run([sys.executable, str(repo / "python/examples" / name), *map(str, args)],
                          capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, f"{name} exited with {done.returncode}:\n{done.stdout}\n{done.stderr[-2000:]}"
    return done.stdout


def test_contact_example_agrees_with_the_oracle(repo, tmp_path):
    out = run_example(repo, tmp_path, "contact_vs_oracle.py", 200, 3)
    assert "200 pairs" in out and "0 statuses differ from the oracle" in out, out


def test_energy_example_prints_its_drift(repo, tmp_path):
    out = run_example(repo, tmp_path, "elastic_impact_energy.py")
    assert "largest |E - E0| / E0" in out, out


def test_sphere_bed_example_runs(repo, tmp_path):
    out = run_example(repo, tmp_path, "sphere_bed_impact.py", 0.002)
    assert "3001 bodies" in out, out
