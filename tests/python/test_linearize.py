"""Linear models (rfem.linearize, Simulation.linearize, rfem linearize): against the modes rfem
computes by its own matrices, against the nonlinear equations' response, and against what an
equilibrium and a solution of the equations must satisfy."""
import os
import subprocess

import h5py
import numpy as np
import pytest
import scipy.linalg as sl

import rfem

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RFEM = os.environ.get("RFEM", os.path.join(ROOT, "build", "apps", "rfem"))


def case_path(name):
    return os.path.join(ROOT, "cases", name)


def test_about_the_equilibrium_the_linear_model_has_rfem_modes(tmp_path):
    """Kane's beam on its hub (the hub prescribed: held): the generalised eigenvalues of (K, M) are
    the frequencies `rfem modes` finds from the assembled matrices, to 1e-8 — the linear model's K is
    a central difference of the residual (Richardson, h = 1e-5), whose round-off is ~1e-10 of a
    column and is amplified in the softest modes (3e-10 measured). Conservative and undamped there:
    K symmetric, M symmetric positive definite, D zero, A's eigenvalues ±iω. The file (rfem.linearize
    output= and `rfem linearize -o`) holds the same matrices with their names."""
    case = rfem.load(case_path("kane_spinup.toml"))
    lin = rfem.linearize(case, n=12, output=tmp_path / "py.h5")
    assert len(lin.states) == 72 and lin.inputs == []  # 6 × 12 rfe coordinates; the hub prescribed
    assert lin.outputs == ["link/tip_u1", "link/tip_u2", "link/tip_theta", "hub/q", "hub/v", "hub/tau"]
    md = rfem.modes(case, n=12, count=6)
    f = np.sqrt(sl.eigh(lin.K, lin.M, eigvals_only=True)[:6]) / (2 * np.pi)
    assert np.abs(f / md.frequencies - 1).max() < 1e-8
    assert np.abs(lin.K - lin.K.T).max() <= 1e-10 * np.abs(lin.K).max()
    assert np.array_equal(lin.M, lin.M.T) and np.linalg.eigvalsh(lin.M).min() > 0
    assert np.abs(lin.D).max() == 0.0
    A, B, C, D = lin.state_space()
    ev = np.linalg.eigvals(A)
    assert np.abs(ev.real).max() < 1e-8 * np.abs(ev).max()
    w = np.sort(np.abs(ev.imag))[::2][:6]
    assert np.abs(w / (2 * np.pi) / md.frequencies - 1).max() < 1e-8
    code = subprocess.run([RFEM, "linearize", case_path("kane_spinup.toml"), "--n", "12", "--threads", "1", "-q",
                           "-o", str(tmp_path / "cli.h5")], capture_output=True, text=True)
    assert code.returncode == 0, code.stderr
    with h5py.File(tmp_path / "py.h5") as a, h5py.File(tmp_path / "cli.h5") as b:
        for name in ("M", "D", "K", "Cq", "A", "C"):
            assert np.array_equal(a["linear/" + name][()], b["linear/" + name][()]), name
        assert np.array_equal(a["linear/K"][()], lin.K)
        assert [s.decode() if isinstance(s, bytes) else s for s in a["linear/C"].attrs["rows"]] == lin.outputs


def test_a_small_torque_step_answers_as_the_nonlinear_equations_do():
    """The two-link arm under its PD laws, held at its initial equilibrium (reference there, the
    feed-forward the torque that holds it), then a torque step δu on the elbow: the forearm's tip
    deflection after 0.3 s from the linear model (exact step response, expm) against the nonlinear
    simulation (tolerances 1e-11, far below the differences). The difference must fall at least as
    δu² (a linear model's error is the equations' second-order term; measured: ×8 per doubling, the
    drives' odd friction law leaving δu³) and be below 1e-4 of the response at δu = 1e-3 N m."""
    case = rfem.load(case_path("two_link_arm.toml"), {"simulation.rtol": 1e-11, "simulation.atol": 1e-14,
                                                      "simulation.atol_velocity": 1e-12})
    T = 0.3

    def held(du):
        sim = rfem.Simulation(case, n=4, threads=1)
        s = sim.snapshot()
        u0 = sim.linearize().u0
        for k, j in enumerate(("shoulder", "elbow")):
            sim.set_reference(j, s["q"][j], 0.0, s["tau"][j] + u0[k] + (du if j == "elbow" else 0.0))
        return sim

    lin = held(0.0).linearize()
    assert np.abs(lin.u0).max() < 1e-9  # the held law holds the state: nothing more is needed
    A, B, C, D = lin.state_space()
    n = A.shape[0]
    aug = np.zeros((n + 1, n + 1))
    aug[:n, :n], aug[:n, n] = A, B[:, lin.inputs.index("elbow")]
    x = sl.expm(aug * T)[:n, n]  # the state after T of a unit step: ∫ e^{As} b ds
    k = lin.outputs.index("forearm/tip_u1")
    errors, responses = [], []
    for du in (1e-3, 2e-3, 4e-3):
        sim = held(du)
        sim.advance(T)
        nonlinear = sim.snapshot()["tip_deflection"]["forearm"][0] - lin.y0[k]
        linear = (C[k] @ x + D[k, lin.inputs.index("elbow")]) * du
        errors.append(abs(nonlinear - linear))
        responses.append(abs(linear))
    assert errors[0] < 1e-4 * responses[0]
    assert errors[1] / errors[0] > 3.5 and errors[2] / errors[1] > 3.5, errors


def test_on_the_motion_the_state_satisfies_the_equations():
    """Linearised on its motion (the state's own accelerations), a state the integrator reached is a
    solution of the equations: the rfe rows' residual ≪ the forces (1e-12 measured) and the free
    joints need no added torque (u0 ≈ 0 against torques of 0.1–1 N m); the PD-controlled arm's
    linear model there is stable (its laws damp every mode)."""
    sim = rfem.Simulation(rfem.load(case_path("two_link_arm.toml")), n=8, threads=1)
    sim.advance(1.0)
    lin = sim.linearize(equilibrium=False)
    assert not lin.equilibrium and lin.t == 1.0
    assert lin.imbalance < 1e-9 and np.abs(lin.u0).max() < 1e-6
    A, _, _, _ = lin.state_space()
    assert np.linalg.eigvals(A).real.max() < 0


def test_bad_arguments():
    case = rfem.load(case_path("kane_spinup.toml"))
    other = rfem.Simulation(rfem.load(case_path("two_link_arm.toml")), n=4).state()
    with pytest.raises(ValueError, match="state is of another model"):
        rfem.linearize(case, n=4, state=other)
    with pytest.raises(TypeError, match=r"^state: must be an rfem.SimulationState or None"):
        rfem.linearize(case, n=4, state="x.h5")
    with pytest.raises(ValueError, match=r"^n: must be a positive integer"):
        rfem.linearize(case, n=0)


def test_the_program_refuses_another_models_state(tmp_path):
    rfem.Simulation(rfem.load(case_path("two_link_arm.toml")), n=4).state().save(str(tmp_path / "other.h5"))
    p = subprocess.run([RFEM, "linearize", case_path("kane_spinup.toml"), "--state", str(tmp_path / "other.h5"),
                        "-o", str(tmp_path / "lin.h5")], capture_output=True, text=True)
    assert p.returncode == 2 and p.stderr.count("\n") == 1
    assert p.stderr.startswith("rfem: error: --state: ") and "the state is of another model" in p.stderr


def test_frequency_response_and_bode(tmp_path):
    """The two-link arm under its PD laws (tolerance 1e-10): (1) rfem.linear.frequency_response
    (the second-order form) is the first-order model's C (jωI − A)⁻¹ B + D, to 1e-8 (both solve
    systems of condition ~1e6; 1.4e-10 measured); (2) a chirp of 1 mN m, 0.2 → 10 Hz over 4 s, on the
    elbow's torque through a 1 kHz controller: the nonlinear forearm tip deflection equals the
    linear model's exact zero-order-hold response within 1e-3 of its peak (the accuracy a control
    design needs; 3.6e-5 measured: the drives' friction law); (3) `rfem bode` draws it (exit 0)
    and refuses an unknown input in one line (exit 2)."""
    case = rfem.load(case_path("two_link_arm.toml"), {"simulation.rtol": 1e-10, "simulation.t_end": 4.0})
    lin = rfem.linearize(case, n=4, output=tmp_path / "lin.h5")
    A, B, C, D = lin.state_space()
    k, i = lin.outputs.index("forearm/tip_u1"), lin.inputs.index("elbow")
    f = np.array([0.3, 2.0, 17.0])
    G = lin.frequency_response(f, "elbow", "forearm/tip_u1")
    for fk, g in zip(f, G):
        w = 2 * np.pi * fk
        ref = C[k] @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B[:, i]) + D[k, i]
        assert abs(g - ref) < 1e-8 * abs(ref)
    assert np.allclose(rfem.linear.frequency_response(str(tmp_path / "lin.h5"), f)[:, k, i], G, rtol=1e-12, atol=0)

    dt, amp, T = 1e-3, 1e-3, 4.0
    u = lambda t: amp * np.sin(2 * np.pi * (0.2 * t + 0.5 * (10 - 0.2) / T * t * t))  # noqa: E731
    start = {}

    def controller(t, y):
        if not start:
            start.update(q=dict(y["q"]), tau=dict(y["tau"]))
        return {"shoulder": (start["q"]["shoulder"], 0.0, start["tau"]["shoulder"]),
                "elbow": (start["q"]["elbow"], 0.0, start["tau"]["elbow"] + u(t))}

    run = rfem.run(case, n=4, threads=1, controller=controller, sample_time=dt)[0]
    assert run.completed
    n2 = A.shape[0]
    aug = np.zeros((n2 + 1, n2 + 1))
    aug[:n2, :n2], aug[:n2, n2] = A, B[:, i]
    E = sl.expm(aug * dt)
    x, linear = np.zeros(n2), [0.0]
    for s in range(int(round(T / dt))):
        x = E[:n2, :n2] @ x + E[:n2, n2] * u(s * dt)  # exact for an input held over each sample
        linear.append(C[k] @ x)
    t = run.column("time", 0)
    linear = np.array(linear)[np.rint(t / dt).astype(int)]
    nonlinear = run.column("links/forearm/tip_deflection", "u1") - lin.y0[k]
    assert np.abs(nonlinear - linear).max() < 1e-3 * np.abs(linear).max()

    ok = subprocess.run([RFEM, "bode", str(tmp_path / "lin.h5"), "--input", "elbow", "--output", "forearm/tip_u1",
                         "-o", str(tmp_path / "bode.png")], capture_output=True, text=True)
    assert ok.returncode == 0 and (tmp_path / "bode.png").stat().st_size > 10000, ok.stderr
    bad = subprocess.run([RFEM, "bode", str(tmp_path / "lin.h5"), "--input", "knee", "--output", "forearm/tip_u1"],
                         capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr == "rfem bode: error: input: no input named 'knee' (have: shoulder, elbow)\n"
