"""rfem.Simulation and controllers in the loop from Python: one advance to the end is rfem.run bit
for bit; a saved state (HDF5, numpy, pickle) continues the original bit for bit; a controller
holding the case's own torque gives the plain run within the integrator's accuracy and keeps the
energy books; bad controllers, states and arguments give TypeError/ValueError with one line; Ctrl-C
in a controller is RunInterrupted with the rows kept."""
import os
import pickle
import tempfile

import h5py
import numpy as np
import pytest

import rfem

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def hub(t_end=0.4, n=6):
    """Kane's beam on a hub driven by 220 N m (drive damping and friction), 6 rfes."""
    return rfem.load(os.path.join(ROOT, "cases", "kane_hub_drive.toml"),
                     overrides=[f"simulation.t_end={t_end}", f"link.n={n}", "simulation.output_dt=0.01"])


def test_one_advance_is_the_run_bit_for_bit():
    case = hub()
    run = rfem.run(case, threads=1)["run"]
    sim = rfem.Simulation(case, threads=1)
    assert sim.advance(sim.t_end) == "completed"
    r = sim.finish()
    assert r.status == "completed"
    for name in ("tip_deflection", "joint_q", "energy"):
        assert np.array_equal(r.table(name), run.table(name)), name
    assert len(sim.q) == len(sim.coordinate_names) == 6 * 6 + 1
    assert sim.coordinate_names[0] == "link/rfe1/x1" and sim.coordinate_names[-1] == "hub"


@pytest.mark.parametrize("how", ["pickle", "h5", "npz"])
def test_a_saved_state_continues_bit_for_bit(tmp_path, how):
    case = hub()
    first = rfem.Simulation(case, threads=1)
    first.advance(0.15)
    state = first.state()
    if how == "pickle":
        state = pickle.loads(pickle.dumps(state))
    elif how == "h5":
        state.save(str(tmp_path / "s.h5"))
        state = rfem.load_state(tmp_path / "s.h5")
    else:
        np.savez(tmp_path / "s.npz", model=state.model, packed=state.pack())
        state = rfem.load_state(tmp_path / "s.npz")
    second = rfem.Simulation(case, state=state, threads=1)
    assert second.time == 0.15
    first.advance(0.4)
    second.advance(0.4)
    assert np.array_equal(first.q, second.q) and np.array_equal(first.v, second.v)
    # Another model's state: one line.
    with pytest.raises(ValueError, match="another model"):
        rfem.Simulation(hub(n=7), state=state)


def test_a_controller_holding_the_case_torque_is_the_plain_run(tmp_path):
    # Steps end at every sample (another step sequence): equal within the default tolerances'
    # accuracy (README, "Performance": 1e-4 of the peaks).
    case = hub()
    plain = rfem.run(case, threads=1)["run"]
    calls = []

    def f(t, y):
        calls.append(t)
        assert set(y) == {"t", "q", "qd", "tau", "tip_position", "tip_deflection"}
        return {"hub": 220.0}

    r = rfem.run_controlled(case, f, sample_time=2e-3, output=tmp_path / "c.h5", threads=1)
    assert r.completed
    assert len(calls) == 200 and calls[1] == 2e-3
    a, b = plain.table("tip_deflection"), r.table("tip_deflection")
    assert np.abs(a - b).max() < 1e-4 * np.abs(a).max()
    assert r.energy_drift < 1e-6 * r.energy_scale
    with h5py.File(tmp_path / "c.h5") as h:
        control = h["run/control"][()]
        assert control.shape == (200, 2) and np.all(control[:, 1] == 220.0)
        assert h["run"].attrs["status"] == "completed"


def test_bad_controllers_and_arguments(tmp_path):
    case = hub(t_end=0.1)
    for f, err, text in [(lambda t, y: 3.0, TypeError, "must return a dict"),
                         (lambda t, y: {"elbow": 1.0}, ValueError, "no joint named 'elbow'"),
                         (lambda t, y: {"hub": float("nan")}, ValueError, "not finite"),
                         (lambda t, y: {"hub": "x"}, TypeError, "expected a number")]:
        with pytest.raises(err, match=text) as e:
            rfem.run_controlled(case, f, sample_time=1e-2, output=tmp_path / "bad.h5")
        assert e.value.run.status.startswith("failed: controller: ")
        with h5py.File(tmp_path / "bad.h5") as h:  # the file says so too
            assert h["run"].attrs["status"].startswith("failed: controller: ")
    for ts, err in [(0.0, ValueError), (-1.0, ValueError), (1.0, ValueError), ("1", TypeError)]:
        with pytest.raises(err):
            rfem.run_controlled(case, lambda t, y: {}, sample_time=ts)

    def boom(t, y):
        if t > 0.05:
            raise RuntimeError("sensor lost")
        return {}

    r = rfem.run_controlled(case, boom, sample_time=1e-2, output=tmp_path / "boom.h5")
    assert r.status.startswith("failed: controller: RuntimeError: sensor lost")
    with h5py.File(tmp_path / "boom.h5") as h:
        assert h["run/time"].shape[0] >= 6  # t = 0 … 0.05 s kept
    sim = rfem.Simulation(case)
    with pytest.raises(ValueError, match="no joint named"):
        sim.set_torque("elbow", 1.0)
    with pytest.raises(ValueError, match="finite"):
        sim.set_torque("hub", float("inf"))
    with pytest.raises(ValueError, match="t_end"):
        sim.advance(1.0)
    with pytest.raises(TypeError):
        rfem.Simulation(case, n=4.5)


def test_ctrl_c_in_a_controller_is_an_interruption(tmp_path):
    case = hub(t_end=0.2)

    def f(t, y):
        if t >= 0.1:
            raise KeyboardInterrupt
        return {"hub": 200.0}

    with pytest.raises(rfem.RunInterrupted) as e:
        rfem.run_controlled(case, f, sample_time=1e-2, output=tmp_path / "i.h5")
    assert e.value.result.status.startswith("interrupted")
    with h5py.File(tmp_path / "i.h5") as h:
        assert h["run/time"].shape[0] >= 11


def test_run_takes_a_controller():
    case = hub(t_end=0.1)

    def f(t, y):
        return {"hub": 200.0}

    a = rfem.run(case, controller=f, sample_time=1e-2, threads=1)["run"]
    b = rfem.run_controlled(case, f, 1e-2, threads=1)
    assert np.array_equal(a.table("joint_q"), b.table("joint_q"))
    with pytest.raises(ValueError, match="sample_time"):
        rfem.run(case, controller=f)


def test_a_runs_sensors_in_memory_are_its_files_and_tip_motion_is_consistent():
    # The sensors table of a run in memory is the file's, bit for bit. Kane's beam spun up by the hub
    # (no gravity), outputs every 1 ms: the tip's velocity sensor is the time derivative of its
    # position (central differences: error h²/6 |p'''| ~ 2e-4 of the peak, bounded by 1e-3), and a
    # tip IMU's specific force has the length of the tip acceleration sensor's vector (in its own
    # axes, no gravity), to round-off. (The acceleration itself carries the suddenly applied torque's
    # kHz modes, which 1 ms samples do not resolve: tests/test_kernels_fd.cpp checks its formula.)
    case = hub(t_end=0.2).with_values({
        "simulation.output_dt": 1e-3,
        "sensors": [{"name": "enc", "kind": "encoder", "joint": "hub"}, {"name": "imu", "kind": "imu"},
                    {"name": "p", "kind": "tip", "quantity": "position"},
                    {"name": "v", "kind": "tip", "quantity": "velocity"},
                    {"name": "a", "kind": "tip", "quantity": "acceleration"}]})
    r = rfem.run(case, threads=1)["run"]
    cols = r.sensor_columns
    assert cols[:9] == ["time", "enc/q", "enc/qd", "imu/wx", "imu/wy", "imu/wz", "imu/fx", "imu/fy", "imu/fz"]
    assert r.sensor_units[6:9] == ["m/s2"] * 3 and r.sensor_units[cols.index("v/x")] == "m/s"
    y = r.sensors
    assert y.shape == (201, 18)
    np.testing.assert_array_equal(y[:, 0], r.column("time", 0))
    with tempfile.TemporaryDirectory() as d:
        f = rfem.run(case, threads=1, output=os.path.join(d, "s.h5"))["run"]
        with h5py.File(os.path.join(d, "s.h5"), "r") as h:
            np.testing.assert_array_equal(h["run/sensors"][()], f.sensors)
    h = 1e-3

    def block(name):
        i = cols.index(name + "/x")
        return y[:, i:i + 3]
    p, v, a = block("p"), block("v"), block("a")
    fd = (p[2:] - p[:-2]) / (2 * h)
    assert np.abs(fd - v[1:-1]).max() < 1e-3 * np.abs(v).max()
    np.testing.assert_allclose(np.linalg.norm(y[:, 6:9], axis=1), np.linalg.norm(a, axis=1), rtol=1e-12, atol=1e-12)


def test_one_simulation_from_two_threads_is_refused_not_a_crash():
    """A Simulation entered by a second thread while the first advances (the GIL released)
    raises RuntimeError in that thread; the first one's run goes on untouched."""
    import threading
    sim = rfem.Simulation(hub(t_end=2.0, n=20), threads=1)
    errors, done = [], []

    def go(k):
        try:
            for _ in range(40):
                sim.advance(min(sim.t_end, sim.time + 0.05))
                sim.set_torque("hub", 100.0 + k)
                sim.snapshot()
            done.append(k)
        except RuntimeError as e:
            errors.append(str(e))
    threads = [threading.Thread(target=go, args=(k,)) for k in range(2)]
    [t.start() for t in threads]
    [t.join() for t in threads]
    assert done or errors
    assert all("in use by another thread" in e for e in errors), errors
    assert sim.finish().status in ("completed", "interrupted (stopped)")


def test_controller_outputs_and_pickles_are_checked_in_rfems_words(tmp_path):
    """A controller's array of two values is a TypeError naming the joint; numpy float32 is a
    number; a tampered pickle is a ValueError, never pybind11's cast message; a huge signal number
    does not wrap."""
    case = hub(t_end=0.2)
    with pytest.raises(TypeError, match=r"joint 'hub': expected a number, got ndarray of shape \(2,\)"):
        rfem.run_controlled(case, lambda t, y: {"hub": np.array([1.0, 2.0])}, 0.01)
    r = rfem.run_controlled(case, lambda t, y: {"hub": np.float32(200.0)}, 0.01)
    assert r.status == "completed"
    s = rfem.Simulation(case)
    s.set_torque("hub", np.float32(2.0))
    s.finish()
    st = list(case.__getstate__())
    st[1] = None
    c = rfem.Case.__new__(rfem.Case)
    with pytest.raises(ValueError, match="not a pickled rfem.Case"):
        c.__setstate__(tuple(st))
    run = rfem.run(case, threads=1)["run"]
    st = list(run.__getstate__())
    st[6] = -1
    o = rfem.Run.__new__(rfem.Run)
    with pytest.raises(ValueError, match="outputs = -1 is negative"):
        o.__setstate__(tuple(st))
    assert rfem.RunStatus.parse("interrupted (signal 99999999999)").signal in (None, 0)
    assert rfem.RunStatus.parse("interrupted (signal 15)").signal == 15


def test_a_results_file_is_a_state_only_while_its_run_has_a_checkpoint(tmp_path):
    # rfem.load_state reads a killed single run's newest checkpoint (one state format; the C++ test
    # Resume.AKilledRunsCheckpointIsASimulationState continues one bit for bit); a run that completed
    # keeps no state at its end: one line naming the file.
    case = hub(t_end=0.1)
    rfem.run(case, output=str(tmp_path / "done.h5"), threads=1)
    with pytest.raises(rfem.CaseError, match=r"done.h5: its run completed"):
        rfem.load_state(tmp_path / "done.h5")
