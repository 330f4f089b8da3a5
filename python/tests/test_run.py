"""The Python module: a run returns history.csv's columns as numpy arrays with the physics the
command line reports (exact EEM energy balance, entropy never decreasing), the summary of
summary.json, frames of rigid bodies and joints; scenes built in code run like their files;
invalid input raises InputError with the file:line message; the GIL is released while a run
integrates."""
import csv
import pathlib
import threading
import time

import numpy as np
import pytest

import metriplex

SCENES = pathlib.Path(__file__).resolve().parents[2] / "scenes"
TWO_SPRINGS = str(SCENES / "two_thermo_springs.xml")


def test_history_columns_match_history_csv_and_the_balance_is_exact(tmp_path):
    r = metriplex.run(TWO_SPRINGS, integrator="eem", dt=0.2, t_end=20, out=str(tmp_path))
    with open(tmp_path / "history.csv") as f:
        rows = list(csv.reader(f))
    assert list(r.history) == rows[0]
    assert len(r.history["time"]) == len(rows) - 1 == 101
    # the same numbers as the file, to the 17 digits it keeps
    for i, name in enumerate(rows[0]):
        np.testing.assert_array_equal(r.history[name], [float(row[i]) for row in rows[1:]])
    energy = r.history["energy"]
    assert np.max(np.abs(energy - energy[0])) / energy[0] < 1e-13
    assert np.all(np.diff(r.history["entropy"]) > -1e-14)
    assert r.history["entropy"][-1] > r.history["entropy"][0] + 0.01
    assert r.summary["status"] == "ok" and r.ok
    assert r.summary["steps"] == 100
    assert r.summary["max_relative_energy_drift"] < 1e-13
    assert r.summary["newton_iterations"] == int(r.history["newton_iterations"].sum())
    assert r.summary["wall_seconds"] > 0


def test_summary_is_summary_json(tmp_path):
    import json

    r = metriplex.run(TWO_SPRINGS, t_end=4, out=str(tmp_path))
    written = json.loads((tmp_path / "summary.json").read_text())
    assert {k: v for k, v in written.items() if k != "wall_seconds"} == {
        k: v for k, v in r.summary.items() if k != "wall_seconds"
    }


def test_no_files_without_out(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    metriplex.run(TWO_SPRINGS, t_end=1)
    assert list(tmp_path.iterdir()) == []


def test_ida_and_its_tolerance():
    r = metriplex.run(TWO_SPRINGS, integrator="ida", rtol=1e-8, dt_out=0.5, t_end=20)
    assert r.summary["integrator"] == "ida" and r.summary["ida"]["steps"] > 0
    assert r.summary["rtol"] == 1e-8
    # the tolerance reached IDA: a looser one takes fewer steps
    loose = metriplex.run(TWO_SPRINGS, integrator="ida", rtol=1e-5, dt_out=0.5, t_end=20)
    assert loose.summary["ida"]["steps"] < r.summary["ida"]["steps"]
    np.testing.assert_allclose(np.diff(r.history["time"]), 0.5, rtol=1e-12)
    # a tolerance-controlled balance: small, but not round-off like EEM's
    assert r.summary["max_relative_energy_drift"] < 1e-5


def test_bodies_and_joints_frames():
    r = metriplex.run(str(SCENES / "double_pendulum.xml"), t_end=0.5, output_interval=0.1)
    assert r.bodies and r.joints
    for pose in r.bodies.values():
        assert list(pose) == ["time", "x", "y", "z", "qw", "qx", "qy", "qz"]
        np.testing.assert_allclose(pose["time"], np.arange(0, 0.51, 0.1), atol=1e-12)
        norm = pose["qw"] ** 2 + pose["qx"] ** 2 + pose["qy"] ** 2 + pose["qz"] ** 2
        np.testing.assert_allclose(norm, 1.0, atol=1e-6)
    for coordinate in r.joints.values():
        assert list(coordinate) == ["time", "position", "velocity"]
        np.testing.assert_allclose(coordinate["time"], np.arange(0, 0.51, 0.1), atol=1e-12)
    # the hinge starts horizontal at rest and falls; its velocity is its position's rate
    hinge = r.joints["hinge"]
    assert hinge["position"][0] == 0.0 and hinge["velocity"][0] == 0.0
    assert hinge["position"][-1] > 0.5
    swept = np.sum(0.5 * (hinge["velocity"][1:] + hinge["velocity"][:-1]) * 0.1)
    assert swept == pytest.approx(hinge["position"][-1], rel=0.05)


def two_springs_in_code():
    scene = metriplex.Scene("two_thermo_springs")
    scene.dt, scene.t_end, scene.thermal_variable = 0.2, 200, "entropy"
    scene.add("anchor", name="origin", position=(0, 0, 0))
    scene.add("mass", name="m1", mass=1.0, position=(1, 0, 0), velocity=(0, 2, 0))
    scene.add("mass", name="m2", mass=1, position=[2.2, 0, 0], velocity=(1, 0, 0))
    for name, a, b, entropy in [("s1", "origin", "m1", 1.0), ("s2", "m1", "m2", 0.2)]:
        scene.add("thermo_spring", name=name, a=a, b=b, stiffness=1, coupling=1, rest_length=1,
                  heat_capacity=1, reference_temperature=1, entropy=entropy)
    scene.add("heat_link", name="h12", a="s1", b="s2", conductivity=1)
    return scene


def test_scene_built_in_code_runs_as_its_file_bit_for_bit():
    from_code = metriplex.run(two_springs_in_code(), t_end=10)
    from_file = metriplex.run(TWO_SPRINGS, t_end=10)
    for name in from_file.history:
        np.testing.assert_array_equal(from_code.history[name], from_file.history[name], err_msg=name)


def test_invalid_input_names_file_and_line(tmp_path):
    bad = tmp_path / "bad.xml"
    bad.write_text('<metriplex name="bad">\n  <simulation dt="0.1" t_end="1"/>\n  <mass name="m" mass="-1"/>\n'
                   "</metriplex>\n")
    with pytest.raises(metriplex.InputError, match=r"bad\.xml:3.*mass"):
        metriplex.run(str(bad))
    with pytest.raises(ValueError, match="unknown integrator 'rk4'"):
        metriplex.run(TWO_SPRINGS, integrator="rk4")
    with pytest.raises(metriplex.InputError, match="positive"):
        metriplex.run(TWO_SPRINGS, dt=-1.0)
    scene = two_springs_in_code()
    scene.add("spring", name="s3", a="m2", b="nowhere", stiffness=1, rest_length=1)
    with pytest.raises(metriplex.InputError, match="built in Python.*nowhere"):
        metriplex.run(scene)
    with pytest.raises(metriplex.InputError, match="attribute 'position'"):
        metriplex.Scene().add("mass", name="m", mass=1.0, position={"x": 1})
    with pytest.raises(metriplex.InputError, match="need an output directory"):
        metriplex.run(TWO_SPRINGS, checkpoint_every=10)


def test_the_gil_is_released_during_a_run():
    # a worker integrates the L-block over its whole t_end (about 0.7 s; t_end 20 took 0.3 s,
    # too close to the guard below)
    ended = {}

    def integrate():
        ended["start"] = time.perf_counter()
        metriplex.run(str(SCENES / "lblock_elastic.xml"), t_end=50)
        ended["end"] = time.perf_counter()

    # the main thread counts its wake-ups while the worker runs; holding the GIL through the
    # run would leave it one or two (before the run starts and after it ends)
    worker = threading.Thread(target=integrate)
    worker.start()
    wake_ups = 0
    while worker.is_alive():
        time.sleep(0.01)
        wake_ups += 1
    worker.join()
    assert ended["end"] - ended["start"] > 0.2, "the run is too short for the test to mean anything"
    assert wake_ups >= 10


def test_budget_per_element_sums_to_the_history():
    r = metriplex.run(str(SCENES / "heated_thermo_spring.xml"), budget=True, t_end=5)
    assert set(r.budget) >= {"bob", "spring"}
    for column in ["energy", "entropy", "boundary_heat", "entropy_production"]:
        total = sum(group[column] for group in r.budget.values())
        scale = max(np.max(np.abs(group[column])) for group in r.budget.values())
        np.testing.assert_allclose(total, r.history[column], rtol=0, atol=1e-12 * scale, err_msg=column)
    with pytest.raises(metriplex.InputError, match="budget"):
        metriplex.run(TWO_SPRINGS, integrator="ida", budget=True)
