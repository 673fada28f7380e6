"""Outputs written from Python are those of `polydem run` (the same engine function opens them): the same
bytes in every series; progress and callbacks do not change them; the contact list and the walls as
arrays agree with what the outputs write."""

import csv

import numpy as np
import pytest

import polydem
from conftest import run

CUBE = "scenes/cube_drop.toml"
UNTIL = 0.3
INTERVALS = {"vtk_interval": 0.05, "contacts_interval": 0.05, "checkpoint_interval": 0.1}


def files_of(directory):
    """Every output file below `directory` by relative path, except the run's identity and lock, the
    summary (written by the command only) and the checkpoints (they hold the run's identity)."""
    skip = {".polydem-run", ".polydem.lock", "summary.txt", "summary.json"}
    return {
        p.relative_to(directory).as_posix(): p.read_bytes()
        for p in sorted(directory.rglob("*"))
        if p.is_file() and p.name not in skip and "checkpoints" not in p.parts
    }


def python_run(repo, out, **kwargs):
    sim = polydem.Simulation.from_toml(repo / CUBE)
    sim.run(until=UNTIL, out=out, **INTERVALS, **kwargs)
    return sim


def test_outputs_are_the_bytes_of_polydem_run(repo, polydem_bin, tmp_path):
    cli, py = tmp_path / "cli", tmp_path / "py"
    run([str(polydem_bin), "run", str(repo / CUBE), "--out", str(cli), "--quiet", "--end-time", repr(UNTIL),
         "--vtk-interval", "0.05", "--contacts-interval", "0.05", "--checkpoint-interval", "0.1"])
    python_run(repo, py)
    expected, got = files_of(cli), files_of(py)
    assert sorted(got) == sorted(expected), f"files: python {sorted(got)}, polydem run {sorted(expected)}"
    differ = [name for name in expected if got[name] != expected[name]]
    assert not differ, f"files that differ from polydem run's: {differ}"
    assert any(name.endswith(".vtu") for name in got) and "contacts.csv" in got, sorted(got)
    # The checkpoints hold the same state (their bytes differ only by the run identity and end time).
    for name in sorted(p.name for p in (cli / "checkpoints").iterdir()):
        a = polydem.Simulation.load(cli / "checkpoints" / name)
        b = polydem.Simulation.load(py / "checkpoints" / name)
        assert (a.step_index, a.time) == (b.step_index, b.time), name
        assert np.array_equal(a.positions(), b.positions()) and np.array_equal(a.velocities(), b.velocities()), name


def test_progress_and_callbacks_do_not_change_the_outputs(repo, tmp_path):
    python_run(repo, tmp_path / "plain")
    seen, calls = [], []
    sim = python_run(repo, tmp_path / "watched", every=0.01, callback=lambda s: calls.append(s.step_index),
                     progress=lambda k, n: seen.append((k, n)))
    assert files_of(tmp_path / "watched") == files_of(tmp_path / "plain"), "outputs changed by the callbacks"
    steps = [k for k, _ in seen]
    assert steps == sorted(steps) and steps[-1] == sim.step_index, f"progress steps {steps[:5]}…{steps[-3:]}"
    assert {n for _, n in seen} == {sim.step_index}, "progress's second argument is the last step"
    assert len(seen) >= 20, f"progress called {len(seen)} times over {sim.step_index} steps"
    assert calls[-1] == sim.step_index and len(calls) == round(UNTIL / 0.01), calls[-3:]


def test_output_intervals_are_checked_and_need_a_directory(repo, tmp_path):
    sim = polydem.Simulation.from_toml(repo / CUBE)
    with pytest.raises(ValueError, match="vtk_interval must be a finite, positive time in seconds, got -1"):
        sim.run(until=0.01, out=tmp_path / "o", vtk_interval=-1.0)
    with pytest.raises(ValueError, match="need an output directory"):
        sim.run(until=0.01, checkpoint_interval=0.1)
    assert sim.step_index == 0, "a refused run must not step"


def test_contact_arrays_are_the_rows_of_contacts_csv(repo, tmp_path):
    sim = polydem.Simulation.from_toml(repo / CUBE)
    sim.run(until=UNTIL, out=tmp_path, contacts_interval=UNTIL)
    with open(tmp_path / "contacts.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if float(r["t"]) == sim.time]
    c = sim.contacts()
    assert len(rows) == len(c["depth"]) > 0, f"{len(rows)} rows at t = {sim.time}, {len(c['depth'])} contacts"
    walls = sim.walls()["names"]
    for k, r in enumerate(rows):
        assert bool(c["wall"][k]) == (r["kind"] == "wall")
        assert (walls[c["a"][k]] if c["wall"][k] else sim.names[c["a"][k]]) == r["a"]
        assert sim.names[c["b"][k]] == r["b"]
        for key, cols in (("point", "px py pz"), ("normal", "nx ny nz"), ("force", "fx fy fz")):
            assert c[key][k].tolist() == [float(r[x]) for x in cols.split()], (key, k, r)
        assert c["depth"][k] == float(r["depth"])
    # The wall's total force is the opposite of the forces its contacts put on the cube.
    assert np.array_equal(sim.walls()["force"][0], -c["force"].sum(axis=0)), (sim.walls()["force"], c["force"])


def test_a_wall_moves_at_the_velocity_set(repo):
    sim = polydem.Simulation.from_toml(repo / CUBE)
    start = sim.walls()["point"][0].copy()
    assert sim.walls()["names"] == ["floor"] and np.array_equal(sim.walls()["normal"][0], [0.0, 0.0, 1.0])
    sim.set_wall_velocity("floor", [0.0, 0.0, -0.5])
    sim.step(100)
    moved = sim.walls()["point"][0] - start
    expected = 100 * sim.dt * -0.5
    assert abs(moved[2] - expected) <= 1e-12 * abs(expected) and moved[0] == moved[1] == 0.0, (moved, expected)
    assert sim.walls()["velocity"][0].tolist() == [0.0, 0.0, -0.5]
    with pytest.raises(KeyError, match='no wall named "roof"; the walls are \\["floor"\\]'):
        sim.set_wall_velocity("roof", [0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="velocity"):
        sim.set_wall_velocity("floor", [0.0, np.nan, 1.0])
