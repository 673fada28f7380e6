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
