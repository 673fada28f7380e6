"""Ctrl-C reaches long calls that run in Rust with the GIL released: `Simulation.step(n)`, `Simulation.run`
and `polydem.rockfill` raise KeyboardInterrupt soon after SIGINT, and a simulation stopped so is at a step
boundary, consistent: stepped on, it gives the bits of a run that was never interrupted."""

import contextlib
import os
import signal
import threading
import time

import pytest

import polydem
from test_simulation import SPHERE_BED, assert_same_state, flat_sphere_variant, state

# The engine looks at Python's signals about every 0.1 s; the bound leaves room for a loaded machine
# (the calls interrupted here would otherwise run for minutes).
LATENCY_BOUND = 2.0
DELAY = 0.3


@contextlib.contextmanager
def ctrl_c_after(delay):
    """Sends SIGINT to this process after `delay` seconds from another thread, as a terminal's Ctrl-C
    reaches it; yields a list that receives the time it was sent. On exit the timer is cancelled or
    waited for, so that the signal cannot arrive after the block."""
    sent = []

    def send():
        sent.append(time.perf_counter())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(delay, send)
    timer.start()
    try:
        yield sent
    finally:
        timer.cancel()
        timer.join()


def interrupted(call):
    """Runs `call` with SIGINT sent after DELAY; the latency from the signal to the KeyboardInterrupt."""
    with pytest.raises(KeyboardInterrupt):
        with ctrl_c_after(DELAY) as sent:
            call()
    latency = time.perf_counter() - sent[0]
    assert latency < LATENCY_BOUND, f"KeyboardInterrupt {latency:.3f} s after SIGINT, bound {LATENCY_BOUND} s"
    return latency


def scene_path(repo, tmp_path, which):
    return repo / SPHERE_BED if which == "general" else flat_sphere_variant(repo, tmp_path)


@pytest.mark.parametrize("which", ["general", "flat"], ids=["general_step", "flat_sphere_layout"])
@pytest.mark.parametrize("how", ["step", "run"])
def test_ctrl_c_stops_a_long_call_at_a_step_boundary(repo, tmp_path, which, how):
    scene = polydem.Scene.from_toml(scene_path(repo, tmp_path, which))
    sim = polydem.Simulation(scene)
    n = 10**7  # minutes of stepping
    if how == "step":
        interrupted(lambda: sim.step(n))
    else:
        interrupted(lambda: sim.run(until=n * sim.dt))
    stopped = sim.step_index
    assert 0 < stopped < n, f"stopped at step {stopped} of {n}"

    reference = polydem.Simulation(scene)
    reference.step(stopped)
    assert_same_state(state(sim), state(reference), f"state at the interrupt (step {stopped})")
    sim.step(50)
    reference.step(50)
    assert_same_state(state(sim), state(reference), f"50 steps on from the interrupt at step {stopped}")


def test_ctrl_c_stops_the_rockfill_experiment(repo, tmp_path):
    stages = []
    interrupted(lambda: polydem.rockfill(tmp_path, bed=repo / "reference/rockfill/quick_bed",
                                         progress=lambda stage, text: stages.append(stage)))
    assert "bed" in stages, stages
    assert not (tmp_path / "monitors.csv").exists(), "an interrupted run writes no monitors"


def test_a_call_from_another_thread_runs_to_its_end(repo):
    """Signal handlers run on Python's main thread only, so a call made from another thread does not
    look for them; it steps as a call from the main thread does, to the same bits."""
    scene = polydem.Scene.from_toml(repo / SPHERE_BED)
    worker_sim = polydem.Simulation(scene)
    errors = []

    def work():
        try:
            worker_sim.step(300)
            worker_sim.run(until=worker_sim.time + 100 * worker_sim.dt)
        except BaseException as e:  # noqa: BLE001 - reported to the main thread below
            errors.append(e)

    worker = threading.Thread(target=work)
    worker.start()
    worker.join()
    assert not errors, f"the worker thread raised {errors[0]!r}"

    main_sim = polydem.Simulation(scene)
    main_sim.step(300)
    main_sim.run(until=main_sim.time + 100 * main_sim.dt)
    assert worker_sim.step_index == main_sim.step_index, (worker_sim.step_index, main_sim.step_index)
    assert_same_state(state(worker_sim), state(main_sim), f"step {main_sim.step_index}, worker against main")
