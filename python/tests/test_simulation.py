"""Simulations from Python: the same bits as `polydem run` on the same scene, checkpoints and pickling
that continue bit for bit, the engine's scene errors, and the GIL released while stepping."""

import csv
import pickle
import threading
from collections import defaultdict

import numpy as np
import pytest

import polydem
from conftest import run

ELASTIC = "scenes/two_polyhedra_elastic.toml"
SPHERE_BED = "scenes/sphere_bed_a_hertz_5ms.toml"


def state(sim):
    return {
        "time": sim.time,
        "step_index": sim.step_index,
        "positions": sim.positions(),
        "velocities": sim.velocities(),
        "orientations": sim.orientations(),
        "angular_velocities": sim.angular_velocities(),
    }


def assert_same_state(a, b, what):
    assert (a["time"], a["step_index"]) == (b["time"], b["step_index"]), what
    for key in ("positions", "velocities", "orientations", "angular_velocities"):
        differ = np.flatnonzero(np.any(a[key] != b[key], axis=1))
        assert differ.size == 0, (
            f"{what}: {key} differ at bodies {differ[:5]}: {a[key][differ[:5]]} vs {b[key][differ[:5]]}"
        )


def rust_rows(polydem_bin, scene, out, end_time=None):
    """The rows of `bodies.csv` written by `polydem run`, grouped by time (in file order)."""
    cmd = [str(polydem_bin), "run", str(scene), "--out", str(out), "--quiet"]
    if end_time is not None:
        cmd += ["--end-time", repr(end_time)]
    run(cmd)
    rows = defaultdict(dict)
    with open(out / "bodies.csv", newline="") as f:
        for row in csv.DictReader(f):
            rows[float(row["t"])][row["id"]] = row
    return rows


def flat_sphere_variant(repo, tmp_path):
    """Sphere bed a with the energy ledger off, so that both sides take the flat sphere layout; the bed
    file's relative path made absolute for the copy in tmp_path."""
    text = (repo / SPHERE_BED).read_text()
    relative = '"../reference/sphere_bed/bed_quick.csv"'
    assert relative in text and "[simulation]\n" in text
    text = text.replace(relative, f'"{(repo / "reference/sphere_bed/bed_quick.csv").as_posix()}"')
    text = text.replace("[simulation]\n", "[simulation]\nenergy_ledger = false\n", 1)
    path = tmp_path / "sphere_bed_a_flat.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "scene, steps",
    [(ELASTIC, None), (SPHERE_BED, 300), ("flat", 300)],
    ids=["two_polyhedra_whole_run", "sphere_bed_a_general_step", "sphere_bed_a_flat_layout"],
)
def test_same_trajectory_as_polydem_run_bit_for_bit(repo, polydem_bin, tmp_path, scene, steps):
    scene = flat_sphere_variant(repo, tmp_path) if scene == "flat" else repo / scene
    sim = polydem.Simulation.from_toml(scene)
    end_time = None if steps is None else steps * sim.dt
    rows = rust_rows(polydem_bin, scene, tmp_path / "out", end_time)
    index = {name: i for i, name in enumerate(sim.names)}
    columns = {
        "positions": ("x", "y", "z"),
        "velocities": ("vx", "vy", "vz"),
        "orientations": ("qw", "qx", "qy", "qz"),
        "angular_velocities": ("wx", "wy", "wz"),
    }
    assert len(rows) > 5, f"{scene}: only {len(rows)} output times"
    for t, bodies in rows.items():
        # Step in the chunks between outputs (several steps per call), landing exactly on the row's time.
        sim.step(round((t - sim.time) / sim.dt))
        assert sim.time == t, f"{scene}: Python time {sim.time!r}, bodies.csv time {t!r}"
        now = state(sim)
        for name, row in bodies.items():
            for key, cols in columns.items():
                expected = [float(row[c]) for c in cols]
                measured = now[key][index[name]].tolist()
                assert measured == expected, f"{scene} t={t!r} body {name} {key}: {measured} vs {expected}"


def test_steps_in_one_call_or_many_agree(repo):
    one, many = (polydem.Simulation.from_toml(repo / ELASTIC) for _ in range(2))
    one.step(300)
    for n in (1, 2, 97, 200):
        many.step(n)
    assert_same_state(state(one), state(many), "step(300) against step(1, 2, 97, 200)")
    assert one.step_index == 300


def test_checkpoint_save_load_and_pickle_continue_bit_for_bit(repo, tmp_path):
    sim = polydem.Simulation(polydem.Scene.from_toml(repo / ELASTIC))
    sim.step(350)  # inside the impact: the contact store and tangential springs must travel too
    path = tmp_path / "state.ckpt"
    assert sim.save(path) == path.stat().st_size
    pickled = pickle.dumps(sim)
    sim.step(300)
    for restored, how in ((polydem.Simulation.load(path), "save/load"), (pickle.loads(pickled), "pickle")):
        assert restored.step_index == 350
        restored.step(300)
        assert_same_state(state(restored), state(sim), how)
        assert restored.energy() == sim.energy(), how


def test_bad_checkpoints(tmp_path):
    with pytest.raises(OSError, match="missing.ckpt"):
        polydem.Simulation.load(tmp_path / "missing.ckpt")
    (tmp_path / "junk.ckpt").write_bytes(b"not a checkpoint at all, just some bytes")
    with pytest.raises(polydem.CheckpointError, match="not a polydem checkpoint"):
        polydem.Simulation.load(tmp_path / "junk.ckpt")


def test_energy_conservation_of_the_elastic_impact(repo):
    """The Rust gate (tests/world_energy.rs) from Python: e = 1, no friction, no gravity, so the ledger's
    balance is the integration error; it stays within 1e-4 of the initial energy at every step."""
    sim = polydem.Simulation.from_toml(repo / ELASTIC)
    e0 = sim.energy()["mechanical"]
    worst = 0.0
    while sim.step_index < sim.end_step:
        sim.step(1)
        worst = max(worst, abs(sim.energy()["balance"]) / e0)
    end = sim.energy()
    assert worst <= 1e-4, f"worst |balance| / E0 = {worst:e} over {sim.end_step} steps, bound 1e-4 (E0 = {e0} J)"
    assert end["rotational_kinetic"] > 1e-2 * e0, (
        f"rotational energy after the eccentric impact {end['rotational_kinetic']:e} J, expected > {1e-2 * e0:e} J"
    )


def edited(repo, old, new):
    text = (repo / ELASTIC).read_text()
    assert old in text
    text = text.replace(old, new, 1)
    line = text[: text.index(new)].count("\n") + 1
    return text, line


def test_scene_errors_carry_file_line_and_field(repo):
    text, line = edited(repo, "restitution = 1.0", "restitution = 1.5")
    with pytest.raises(polydem.SceneError) as err:
        polydem.Scene.from_string(text, "broken.toml")
    e = err.value
    assert isinstance(e, ValueError)
    assert (e.path, e.line, e.field) == ("broken.toml", line, "interaction[0].restitution"), str(e)
    assert str(e).startswith(f"broken.toml:{line}: interaction[0].restitution: ") and "1.5" in str(e), str(e)

    text, line = edited(repo, "velocity = [1.0", "velocty = [1.0")
    with pytest.raises(polydem.SceneError) as err:
        polydem.Scene.from_string(text, "typo.toml")
    assert err.value.line == line and "unknown field `velocty`" in str(err.value), str(err.value)

    with pytest.raises(polydem.SceneError, match="cannot read the scene file") as err:
        polydem.Scene.from_toml(repo / "scenes" / "no_such_scene.toml")
    assert err.value.line is None


def test_step_releases_the_gil(repo):
    sim = polydem.Simulation.from_toml(repo / SPHERE_BED)
    ticks, stop = [0], threading.Event()

    def count():
        while not stop.is_set():
            ticks[0] += 1

    thread = threading.Thread(target=count)
    thread.start()
    try:
        before = ticks[0]
        sim.step(200)  # tens of milliseconds in Rust; the counter only moves if the GIL is free
        during = ticks[0] - before
    finally:
        stop.set()
        thread.join()
    assert during > 1000, f"the other thread counted {during} times during sim.step(200)"


def test_state_arrays_are_copies(repo):
    sim = polydem.Simulation.from_toml(repo / ELASTIC)
    p = sim.positions()
    p[:] = 0.0
    assert np.any(sim.positions() != 0.0)
    before = sim.positions()
    sim.step(10)
    assert np.any(sim.positions() != before), "a step moves the bodies"
    assert sim.positions().shape == (2, 3) and sim.orientations().shape == (2, 4)


def test_run_with_callbacks_equals_step(repo):
    ran, stepped = (polydem.Simulation.from_toml(repo / ELASTIC) for _ in range(2))
    seen = []
    every = 50 * ran.dt
    ran.run(until=ran.end_time, every=every, callback=lambda s: seen.append((s.step_index, s.positions())))
    expected_steps = list(range(50, ran.end_step, 50)) + [ran.end_step]
    assert [i for i, _ in seen] == expected_steps, [i for i, _ in seen]
    stepped.step(50)
    assert seen[0][1].tolist() == stepped.positions().tolist()
    stepped.step(ran.end_step - 50)
    assert_same_state(state(ran), state(stepped), "run(until, every, callback) against step(n)")


def test_run_stops_at_a_callback_exception_and_refuses_a_past_time(repo):
    sim = polydem.Simulation.from_toml(repo / ELASTIC)

    def stop(s):
        if s.step_index >= 20:
            raise KeyboardInterrupt("enough")

    with pytest.raises(KeyboardInterrupt, match="enough"):
        sim.run(every=10 * sim.dt, callback=stop)
    assert sim.step_index == 20
    with pytest.raises(ValueError, match="until: end time .* lies before the current time"):
        sim.run(until=sim.dt)
    with pytest.raises(ValueError, match="every: expected a finite positive time"):
        sim.run(every=-1.0)


def test_contact_forces_balance_between_the_two_bodies(repo):
    sim = polydem.Simulation.from_toml(repo / ELASTIC)
    with pytest.raises(RuntimeError, match="no contact forces yet"):
        sim.forces()
    sim.step(1)
    assert np.all(sim.forces() == 0.0), "apart at the start: no contact force"
    while not np.any(sim.forces() != 0.0):
        assert sim.step_index < sim.end_step, "the boxes never touched"
        sim.step(1)
    sim.step(50)  # well inside the impact (about 200 steps long)
    f, torques = sim.forces(), sim.torques()
    scale = np.abs(f).max()
    assert scale > 0.0, f"the boxes are in contact at step {sim.step_index}"
    assert np.allclose(f[0] + f[1], 0.0, rtol=0, atol=1e-12 * scale), f"action and reaction: {f}"
    assert torques.shape == (2, 3) and np.any(torques != 0.0), "the off-centre contact exerts torques"
