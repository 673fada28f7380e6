"""Scenes built in Python go through the scene builder of the files: the same world, the same errors."""

import numpy as np
import pytest

import polydem

CUBE_DROP = {
    "simulation": {"gravity": [0.0, 0.0, -9.81], "end_time": 1.0, "output_interval": 0.002,
                   "steps_per_contact": 50},
    "material": [{"name": "rock", "density": 2600.0}],
    "interaction": [{"materials": ["rock", "rock"], "law": "linear", "normal_stiffness": 1.0e6,
                     "restitution": 0.4, "tangential_stiffness": 5.0e5, "friction": 0.5}],
    "shape": [{"name": "cube", "kind": "box", "half_extents": np.array([0.05, 0.05, 0.05])}],
    "body": [{"name": "cube", "shape": "cube", "material": "rock", "position": (0.0, 0.0, 0.2),
              "axis_angle": [0.3, 0.5, 0.1], "angular_velocity": [0.0, 2.0, 0.0], "track": True}],
    "wall": [{"name": "floor", "material": "rock", "point": [0, 0, 0], "normal": [0.0, 0.0, 1.0]}],
}


def test_a_dict_scene_steps_as_its_file(repo):
    from_file = polydem.Simulation.from_toml(repo / "scenes/cube_drop.toml")
    from_dict = polydem.Simulation(polydem.Scene.from_dict(CUBE_DROP))
    from_file.step(400)
    from_dict.step(400)
    for what in ("positions", "velocities", "orientations", "angular_velocities"):
        a, b = getattr(from_file, what)(), getattr(from_dict, what)()
        assert np.array_equal(a, b), f"{what}: file {a}, dict {b}"


def test_dict_scene_errors_are_the_scene_builders(repo):
    bad = {**CUBE_DROP, "body": [{**CUBE_DROP["body"][0], "material": "granite"}]}
    with pytest.raises(polydem.SceneError) as err:
        polydem.Scene.from_dict(bad, path="my_scene")
    assert err.value.path == "my_scene" and "granite" in str(err.value), str(err.value)
    line = polydem.scene_to_toml(bad).splitlines()[err.value.line - 1]
    assert "granite" in line, f"line {err.value.line} of the generated text is {line!r}"
    with pytest.raises(TypeError, match=r"body\[0\]\.position: a object is not a scene value"):
        polydem.Scene.from_dict({**CUBE_DROP, "body": [{**CUBE_DROP["body"][0], "position": object()}]})
    with pytest.raises(TypeError, match=r"shape\[0\]\.half_extents\[1\]: a object"):
        polydem.Scene.from_dict({**CUBE_DROP, "shape": [{"name": "cube", "kind": "box",
                                                         "half_extents": [0.1, object(), 0.1]}]})


def test_none_leaves_an_optional_field_out():
    with_none = {**CUBE_DROP, "body": [{**CUBE_DROP["body"][0], "velocity": None}]}
    assert "\nvelocity = " not in polydem.scene_to_toml(with_none), polydem.scene_to_toml(with_none)
    assert polydem.Scene.from_dict(with_none).num_bodies == 1


def test_bodies_from_columns(repo):
    rng = np.random.default_rng(7)
    n = 12
    xyz = np.column_stack([np.arange(n) * 0.3, np.zeros(n), 0.5 + rng.random(n)])
    rows = polydem.bodies("grain", count=n, shape="cube", material="rock", position=xyz,
                          velocity=(0.0, 0.0, -1.0), track=[i % 2 == 0 for i in range(n)])
    assert [r["name"] for r in rows[:3]] == ["grain0", "grain1", "grain2"] and rows[5]["velocity"] == [0.0, 0.0, -1.0]
    sim = polydem.Simulation(polydem.Scene.from_dict({**CUBE_DROP, "body": rows}))
    assert sim.names == [f"grain{i}" for i in range(n)]
    assert np.array_equal(sim.positions(), xyz), "positions as given (the cube's centroid is its origin)"
    assert np.array_equal(sim.velocities(), np.tile([0.0, 0.0, -1.0], (n, 1)))
    with pytest.raises(ValueError, match="position: a column of 11 entries for 12 bodies"):
        polydem.bodies("grain", count=n, shape="cube", position=xyz[:11])
    with pytest.raises(ValueError, match="a prefix needs count"):
        polydem.bodies("grain", position=xyz)


def test_time_step_check_is_a_scene_key():
    assert polydem.Scene.from_dict({**CUBE_DROP, "simulation": {**CUBE_DROP["simulation"],
                                                                "time_step_check": "warn"}}).num_bodies == 1
    with pytest.raises(polydem.SceneError) as err:
        polydem.Scene.from_dict({**CUBE_DROP, "simulation": {**CUBE_DROP["simulation"], "time_step_check": "maybe"}})
    assert "time_step_check" in str(err.value), str(err.value)


def test_a_run_beyond_the_step_limit_is_refused_unless_raised(repo):
    sim = polydem.Simulation.from_toml(repo / "scenes/cube_drop.toml")
    with pytest.raises(ValueError, match="until: .*limit"):
        sim.run(until=1e9)
    with pytest.raises(ValueError, match="until: .*limit of 10 steps"):
        sim.run(until=0.01, max_steps=10)
    sim.run(until=0.01, max_steps=10**6)
    assert sim.step_index == round(0.01 / sim.dt) and abs(sim.time - 0.01) <= sim.dt, (sim.step_index, sim.time)
