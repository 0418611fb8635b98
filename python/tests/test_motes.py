"""The Python module against the command line and its own promises (pytest, Debian's
/usr/bin/python3 with python3-pytest and python3-numpy). ctest runs it with PYTHONPATH at the
build's python/ folder, MOTES_CLI_PATH at the motes command and MOTES_SOURCE_DIR at the source."""
import csv
import os
import re
import subprocess
import sys

import numpy as np
import pytest

import motes

SOURCE = os.environ.get("MOTES_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
CLI = os.environ.get("MOTES_CLI_PATH", "motes")
DOMINOES = os.path.join(SOURCE, "examples", "scenes", "dominoes.json")


def cli_hash(scene, steps, backend):
    out = subprocess.run([CLI, "run", scene, "--steps", str(steps), "--every", str(steps),
                          "--format", "none", "--backend", backend],
                         check=True, capture_output=True, text=True).stdout
    return int(re.search(r"state hash\s+([0-9a-f]{16})", out).group(1), 16)


def test_dominoes_fall_the_same_as_from_the_command_line():
    sim = motes.Simulation(motes.load_scene(DOMINOES), backend="openmp")
    sim.step(400)
    assert sim.steps == 400
    assert sim.state_hash() == cli_hash(DOMINOES, 400, "openmp")


def test_a_scene_from_a_dict_is_the_scene_from_its_file():
    import json
    with open(DOMINOES) as f:
        as_dict = json.load(f)
    a = motes.Simulation(motes.load_scene(as_dict), backend="openmp")
    b = motes.Simulation(motes.load_scene(DOMINOES), backend="openmp")
    a.step(50)
    b.step(50)
    assert a.state_hash() == b.state_hash()


def test_state_arrays_have_the_documented_shapes():
    sim = motes.Simulation(motes.default_scene(), backend="openmp")
    sim.step(10)
    n, b = sim.particle_count, sim.body_count
    assert (n, b) == (600, 40)
    for array, shape, dtype in [(sim.positions(), (n, 3), np.float32),
                                (sim.velocities(), (n, 3), np.float32),
                                (sim.radii(), (n,), np.float32),
                                (sim.particle_bodies(), (n,), np.uint32),
                                (sim.body_positions(), (b, 3), np.float32),
                                (sim.body_orientations(), (b, 4), np.float32),
                                (sim.body_velocities(), (b, 3), np.float32),
                                (sim.body_angular_velocities(), (b, 3), np.float32)]:
        assert array.shape == shape and array.dtype == dtype
    q = sim.body_orientations()
    assert np.allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-6)
    # Copies: changing one changes nothing in the simulation.
    p = sim.positions()
    p[:] = 0.0
    assert not np.array_equal(sim.positions(), p)
    assert len(sim.body_names) == b and sim.body_names[0] == "first"


def test_a_fluid_scene_runs_and_names_its_kinds():
    # examples/scenes/fluid_floating.json: three cubes and the water after them; the water's
    # particles follow the cubes' and keep their mass (rest density x d^3 = 1 g).
    sim = motes.Simulation(motes.load_scene(os.path.join(SOURCE, "examples", "scenes",
                                                         "fluid_floating.json")),
                           backend="openmp")
    assert sim.body_names == ["cork", "pine", "oak", "water"]
    assert sim.body_kinds == ["rigid", "rigid", "rigid", "fluid"]
    sim.step(2)
    water = sim.particle_bodies() == 3
    assert water.sum() == 3000
    assert np.all(np.isfinite(sim.positions()[water]))
    assert sim.positions()[water][:, 1].min() > 0.0


def test_set_body_velocities_moves_the_particles_with_their_body():
    sim = motes.Simulation(motes.default_scene(), backend="openmp")
    v = np.zeros((sim.body_count, 3))
    w = np.zeros((sim.body_count, 3))
    v[5] = [0.1, 0.2, -0.3]
    w[5] = [0.0, 0.0, 2.0]
    sim.set_body_velocities(v, w)
    assert np.allclose(sim.body_velocities()[5], v[5], atol=1e-7)
    assert np.allclose(sim.body_angular_velocities()[5], w[5], atol=1e-6)
    # A particle's velocity is v + w x r, r from the body's centre.
    mine = sim.particle_bodies() == 5
    r = sim.positions()[mine] - sim.body_positions()[5]
    expected = v[5] + np.cross(w[5], r)
    assert np.allclose(sim.velocities()[mine], expected, atol=1e-6)
    with pytest.raises(motes.Error, match="expected an array of shape"):
        sim.set_body_velocities(np.zeros((3, 3)))


def test_bad_scenes_raise_with_the_file_and_the_path():
    with pytest.raises(motes.Error, match=r"<dict>: /settings/dtt: unknown key"):
        motes.load_scene({"settings": {"dtt": 1e-4}, "bodies": []})
    bad = os.path.join(SOURCE, "tests", "data", "scenes", "bad", "negative_dt.json")
    with pytest.raises(motes.Error, match=re.escape(bad)):
        motes.load_scene(bad)
    with pytest.raises(motes.Error, match="cannot open|No such file"):
        motes.load_scene("/no/such/scene.json")


def test_a_missing_backend_raises_with_the_reason():
    with pytest.raises(motes.Error, match="nosuch"):
        motes.Simulation(motes.default_scene(), backend="nosuch")
    for report in motes.devices():
        if report["compiled"] and not report["devices"]:
            with pytest.raises(motes.Error) as raised:
                motes.Simulation(motes.default_scene(), backend=report["backend"])
            assert report["unavailable_reason"] in str(raised.value)


def test_frame_writer_writes_particles_and_the_body_table(tmp_path):
    sim = motes.Simulation(motes.default_scene(), backend="openmp")
    writer = motes.FrameWriter(str(tmp_path), "csv", sim.body_names)
    for _ in range(3):
        writer.write(sim)
        sim.step(20)
    writer.close()
    assert writer.frames == 3
    with open(tmp_path / "bodies.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 3 * sim.body_count
    assert rows[-1]["name"] == sim.body_names[-1]
    with pytest.raises(motes.Error, match="unknown output format"):
        motes.FrameWriter(str(tmp_path), "xml")


def test_the_readme_example_runs():
    env = dict(os.environ, PYTHONPATH=os.path.dirname(os.path.abspath(motes.__file__)))
    out = subprocess.run([sys.executable, os.path.join(SOURCE, "python", "example.py")],
                         cwd=SOURCE, env=env, check=True, capture_output=True, text=True).stdout
    assert re.match(r"\w+: t = 0\.030 s, lowest particle at y = [0-9.]+ m, 40 bodies", out), out


def test_a_scene_too_big_for_the_device_raises_what_the_command_line_prints():
    # Device limits (docs/reliability.md): the module goes through the check of
    # Simulation::create, as `motes run` does, and raises its message. Lavapipe's
    # maxStorageBufferRange (128 MiB) is below a quarter of this scene's neighbour list (Vulkan
    # splits a list into at most four buffers of columns: 163,840,000 bytes each here).
    lavapipe = [d["index"] for r in motes.devices() if r["backend"] == "vulkan"
                for d in r["devices"] if "llvmpipe" in d["name"]]
    if not lavapipe:
        pytest.skip("needs lavapipe, whose maxStorageBufferRange is 128 MiB")
    scene = os.path.join(SOURCE, "tests", "data", "cli", "big_neighbour_list.json")
    with pytest.raises(motes.Error) as raised:
        motes.Simulation(motes.load_scene(scene), backend="vulkan", device=lavapipe[0])
    cli = subprocess.run([CLI, "run", scene, "--backend", "vulkan", "--device", str(lavapipe[0]),
                          "--steps", "1", "--format", "none"], capture_output=True, text=True)
    assert cli.returncode == 2
    assert cli.stderr.strip() == "motes: error: " + str(raised.value)
    assert "at most 131072 particles fit" in str(raised.value)


def test_check_motion_names_the_fastest_particle_and_reports_the_energy():
    sim = motes.Simulation(motes.default_scene(), backend="openmp")
    # The first check takes the energy guard's reference: the chain at rest, the first domino
    # tipped (the body with the most kinetic energy, a rigid body: no particle named).
    report = sim.check_motion()
    # E0 is the energy measured then plus the contacts' stored energy, which is no longer counted.
    assert report["reference_step"] == 0 and report["rise"] == -report["contact_energy0"]
    assert report["energy0"] == pytest.approx(report["energy"] + report["contact_energy0"])
    assert report["energy"] == pytest.approx(report["kinetic_energy"] + report["potential_energy"])
    assert report["largest_kinetic_body"] == 0 and report["largest_kinetic_particle"] is None
    assert report["margin"] > 0.0 and report["speed_limit"] > report["speed"]
    sim.step(300)
    report = sim.check_motion()
    assert report["reference_step"] == 0
    assert report["rise"] <= report["largest_rise"] < report["margin"]
    # Velocities set from outside: a new reference, whose energy is theirs.
    v = np.zeros((sim.body_count, 3))
    w = np.zeros((sim.body_count, 3))
    sim.set_body_velocities(v, w)
    assert not sim.check_motion()["moving"]
    v[5] = [3.0, 0.0, 0.0]
    sim.set_body_velocities(v, w)
    report = sim.check_motion()
    assert report["moving"] and report["body"] == 5 and report["warning"] == ""
    assert np.isclose(report["speed"], 3.0, rtol=1e-6)
    scene = motes.default_scene()
    assert np.isclose(report["travel"], 3.0 * scene.dt / report["diameter"], rtol=1e-5)
    assert report["reference_step"] == 300
    assert report["rise"] == pytest.approx(-report["contact_energy0"])
    assert report["contact_energy0"] > 0.0  # the dominoes lying on the floor and on each other
    domino = 15 * 1000.0 * 0.01 ** 3  # 1 x 5 x 3 particles of 1 cm at 1000 kg/m^3
    assert np.isclose(report["kinetic_energy"], 0.5 * domino * 9.0, rtol=1e-5)
    assert report["largest_kinetic_body"] == 5
    # Even 1e9 m/s is a new reference, not an error: set_body_velocities is energy from outside.
    v[5] = [1e9, 0.0, 0.0]
    sim.set_body_velocities(v, w)
    report = sim.check_motion()
    assert np.isclose(report["energy0"] - report["potential_energy"], 0.5 * domino * 1e18, rtol=1e-5)

