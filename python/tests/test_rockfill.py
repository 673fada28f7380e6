"""The rockfill experiment from Python: the run of `polydem rockfill` (the same outputs, byte for byte),
with the monitors as arrays equal to the rows of its monitors.csv."""

import csv

import numpy as np
import pytest

import polydem
from conftest import run

BED = "reference/rockfill/quick_bed"


def test_rockfill_from_a_saved_bed_is_the_commands_run(repo, polydem_bin, tmp_path):
    cli, py = tmp_path / "cli", tmp_path / "py"
    run([str(polydem_bin), "rockfill", "--bed", str(repo / BED), "--out", str(cli)])
    stages = []
    r = polydem.rockfill(py, bed=repo / BED, progress=lambda stage, text: stages.append(stage))
    assert (py / "monitors.csv").read_bytes() == (cli / "monitors.csv").read_bytes(), "monitors.csv differs"
    assert r["outcome"] == "exited" and 1000.0 < r["residual_speed"] < 1125.0, (r["outcome"], r["residual_speed"])
    assert "penetration" in stages, stages[:5]
    m = r["monitors"]
    with open(py / "monitors.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(m["time"]) == r["steps"], (len(rows), len(m["time"]), r["steps"])
    last = rows[-1]
    assert m["time"][-1] == float(last["t"]) and m["speed"][-1] == float(last["speed"])
    assert m["position"][-1].tolist() == [float(last[k]) for k in ("x", "y", "z")]
    assert m["contacts"].dtype == np.int64 and m["force"].shape == (r["steps"], 3)
    assert r["residual_speed"] == pytest.approx(np.linalg.norm(m["velocity"][-1]), rel=0, abs=0)


def test_rockfill_refuses_bad_parameters(tmp_path):
    with pytest.raises(ValueError, match="size_mm: must be a positive size in mm, got -5"):
        polydem.rockfill(tmp_path, size_mm=-5.0)
    with pytest.raises(ValueError, match='config: expected "quick", "paper" or the path'):
        polydem.rockfill(tmp_path, config=3)
    with pytest.raises(RuntimeError, match="no_such_bed"):
        polydem.rockfill(tmp_path, bed=tmp_path / "no_such_bed")
