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
    K, M = lin.K.toarray(), lin.M.toarray()  # (scipy.sparse)
    f = np.sqrt(sl.eigh(K, M, eigvals_only=True)[:6]) / (2 * np.pi)
    assert np.abs(f / md.frequencies - 1).max() < 1e-8
    assert np.abs(K - K.T).max() <= 1e-10 * np.abs(K).max()
    assert np.array_equal(M, M.T) and np.linalg.eigvalsh(M).min() > 0
    assert lin.D.nnz == 0
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
        t = a["linear/K"][()]  # sparse: (row, column, value), 0-based
        assert np.array_equal(np.asarray(lin.K.tocoo().todense())[t[:, 0].astype(int), t[:, 1].astype(int)], t[:, 2])
        assert len(t) == lin.K.nnz and len(a["linear/K"].attrs["matrix_columns"]) == 72
        assert [s.decode() if isinstance(s, bytes) else s for s in a["linear/C"].attrs["rows"]] == lin.outputs
    from rfem import linear
    back = linear.LinearFile(tmp_path / "cli.h5")
    assert (back.K != lin.K).nnz == 0 and (back.M != lin.M).nnz == 0


def test_a_structure_without_joints_has_a_linear_model(tmp_path):
    """Kane's clamped beam (cases/kane_beam.toml: no joints, no [simulation] table): the linear
    model exists (it was refused: "a run needs at least one base joint"), has no inputs, and its
    generalised eigenvalues are `rfem modes`' frequencies to 1e-8 (the bound of the test above:
    central differences' round-off in the softest modes). The program writes the same K."""
    case = rfem.load(case_path("kane_beam.toml"))
    lin = rfem.linearize(case, n=10)
    assert len(lin.states) == 60 and lin.inputs == [] and lin.outputs == ["link/tip_u1", "link/tip_u2", "link/tip_theta"]
    md = rfem.modes(case, n=10, count=6)
    f = np.sqrt(sl.eigh(lin.K.toarray(), lin.M.toarray(), eigvals_only=True)[:6]) / (2 * np.pi)
    assert np.abs(f / md.frequencies - 1).max() < 1e-8
    code = subprocess.run([RFEM, "linearize", case_path("kane_beam.toml"), "--n", "10", "--threads", "1", "-q",
                           "-o", str(tmp_path / "beam.h5")], capture_output=True, text=True)
    assert code.returncode == 0, code.stderr
    with h5py.File(tmp_path / "beam.h5") as b:
        t = b["linear/K"][()]
        assert np.array_equal(np.asarray(lin.K.tocoo().todense())[t[:, 0].astype(int), t[:, 1].astype(int)], t[:, 2])


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
    with pytest.raises(TypeError, match=r"^dense: "):
        rfem.linearize(case, n=4, dense="yes")
    lin = rfem.linearize(case, n=4)
    with pytest.raises(ValueError, match=r"^count: must be 1 or more"):
        lin.modes(0)


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


FREE = {"kind": "torque", "value": 0.0}
SENSORS = [{"name": "eps", "kind": "strain", "link": "forearm", "at": 0.3, "face": "y", "distance": 0.002},
           {"name": "enc", "kind": "encoder", "joint": "elbow"}, {"name": "trq", "kind": "torque", "joint": "shoulder"},
           {"name": "acc", "kind": "tip", "link": "forearm", "quantity": "acceleration"},
           {"name": "imu", "kind": "imu", "link": "upper", "at": 0.5}]


@pytest.mark.parametrize("name, values, n, moving", [
    ("two_link_arm.toml", {}, 8, False),  # PD laws, drive friction, a damped link
    ("two_link_arm.toml", {"sensors": SENSORS, "joints.0.input": {"kind": "constant_rate", "rate": 0.5}}, 9, True),
    ("paper_two_flexible.toml", {"simulation.procedure": "single", "joints.2.input": FREE}, 9, False),  # a joint on link 2's tip
    ("wrist_payload.toml", {"joints.0.input": FREE}, 10, False),  # a wrist on the tip, a body at mid-span
    ("space_deployment.toml", {}, 6, True),  # the free bus, on the motion at t = 0.5 s
    ("kane_spinup.toml", {"link.modes": 4, "joints.0.input": FREE}, 12, True),  # a reduced link
    ("urdf_arm.toml", {}, 6, False),  # a URDF base, gravity
])
def test_the_sparse_linear_model_is_the_column_by_column_one(name, values, n, moving):
    """The sparse method (18 evaluations per difference whatever n, node rows split per rfe) against
    differencing the equations column by column (9 evaluations per state): the same matrices to the
    differences' round-off — every column is the same difference of the same residual, summed in
    other chunks (1e-16 of a term over h = 1e-5: ~1e-11 of the matrix's largest entry). Models with
    a carrying rfe, a body at mid-span, a free base, a reduced link, a URDF base, every kind of
    sensor (their outputs and a prescribed joint's torque see every rfe); about rest and about the
    motion (gyroscopic D)."""
    case = rfem.load(case_path(name), values)
    with rfem.Simulation(case, n=n, threads=1) as sim:
        if moving:
            sim.advance(0.5)
        lin = sim.linearize(equilibrium=not moving)
        ref = sim.linearize(equilibrium=not moving, dense=True)
    assert lin.states == ref.states and lin.outputs == ref.outputs and lin.inputs == ref.inputs
    for m in ("M", "D", "K", "B", "Cq", "Cv", "Ca"):
        a, b = getattr(lin, m), getattr(ref, m)
        a, b = (x.toarray() if hasattr(x, "toarray") else x for x in (a, b))
        if b.size == 0:  # (no inputs)
            continue
        scale = max(np.abs(b).max(), 1e-300)
        assert np.abs(a - b).max() <= 1e-9 * scale, (m, np.abs(a - b).max() / scale)
    assert lin.evaluations < ref.evaluations or len(lin.states) < 20
    np.testing.assert_allclose(lin.u0, ref.u0, rtol=0, atol=1e-12 * (1 + np.abs(ref.u0).max(initial=0)))


def test_the_cost_does_not_grow_with_n():
    """The paper's deployment at n = 60 and 600: the same number of evaluations of the equations
    (18 per difference: rfes three apart, six axes), and the lowest frequencies of A at n = 600
    (shift-invert on the sparse pencil, 3 600 states) are `rfem modes`' to the differences'
    round-off: 3e-10 at n = 12 (the first test), amplified in the softest modes by the stiffness
    ratio, which grows as n²: 7.5e-7 at n = 600 (1.0e-7 measured)."""
    case = rfem.load(case_path("paper_deployment.toml"))
    a = rfem.linearize(case, n=60)
    b = rfem.linearize(case, n=600)
    assert a.evaluations == b.evaluations
    assert len(b.states) == 3600 and b.K.nnz < 40 * 3600
    f = np.array([x[0] for x in b.modes(4)])
    md = np.asarray(rfem.modes(case, n=600, count=4).frequencies)
    assert np.abs(f / md - 1).max() < 3e-10 * (600 / 12) ** 2, (f, md)
    with pytest.raises(ValueError, match="3000"):
        b.state_space()


def test_a_damped_models_modes_are_the_damped_modes():
    """Kane's beam with its hub held and stiffness-proportional sde damping (damping_beta = β): at
    rest and undeformed (no gravity, no preload) D = β K, so every mode keeps its shape and its
    eigenvalues are −ζω ± iω√(1 − ζ²) with ζ = βω/2 and ω `rfem modes`' undamped frequency (the
    damped modes in closed form). Dense (72 states) and shift-invert (n = 30: 180 states) both, to
    the linear model's 1e-8 (the first test)."""
    beta = 2e-3
    for n in (12, 30):
        case = rfem.load(case_path("kane_spinup.toml"), {"link.damping_beta": beta})
        lin = rfem.linearize(case, n=n)
        K, D = lin.K.toarray(), lin.D.toarray()
        assert np.abs(D - beta * K).max() <= 1e-8 * beta * np.abs(K).max()
        w = 2 * np.pi * np.asarray(rfem.modes(case, n=n, count=6).frequencies)
        zeta = beta * w / 2
        got = np.array(lin.modes(6))
        assert np.abs(got[:, 1] / zeta - 1).max() < 1e-8, (got[:, 1], zeta)
        assert np.abs(got[:, 0] / (w / (2 * np.pi)) - 1).max() < 1e-8  # (|λ| = ω)


def test_the_descriptor_form_answers_as_the_second_order_form():
    """LinearModel.descriptor(): E x' = A x + B u, y = C x over x = (q, q', q'') — sparse, any size
    (state_space() is dense). Its transfer function C (jωE − A)⁻¹ B is the second-order form's
    (Cq + jω Cv − ω² Ca)(K + jωD − ω²M)⁻¹ B: the same algebra eliminated in another order, so equal
    to the solves' round-off, ε times the condition of K + jωD − ω²M (its stiff sdes over the slow
    modes' ω²M: ~1e9 here, 1e-7 allowed; 3.8e-9 measured), on the PD arm with a prescribed
    shoulder (Ca ≠ 0: its torque is an output) at n = 200 (1 200 states: more than a file holds as a
    dense first-order model)."""
    import scipy.sparse.linalg as sla
    from rfem import linear
    case = rfem.load(case_path("two_link_arm.toml"), {"joints.0.input": {"kind": "constant_rate", "rate": 0.0}})
    lin = rfem.linearize(case, n=200)
    E, A, B, C = lin.descriptor()
    N = len(lin.states)
    assert E.shape == (3 * N, 3 * N) and B.shape == (3 * N, 1) and C.shape == (len(lin.outputs), 3 * N)
    assert E.diagonal()[:2 * N].min() == 1 and E.diagonal()[2 * N:].max() == 0
    out = lin.outputs.index("shoulder/tau")
    assert np.abs(lin.Ca[out]).max() > 0
    for f in (0.3, 4.0):
        w = 2 * np.pi * f
        X = sla.spsolve((1j * w * E - A).tocsc().astype(complex), B.toarray().astype(complex))
        G = C @ X
        ref = linear.frequency_response(lin, [f], "elbow")[0][:, 0]
        assert np.abs(G - ref).max() <= 1e-7 * np.abs(ref).max(), (f, np.abs(G - ref).max())


def test_a_free_hubs_modes_come_out_of_the_shift_invert_solver():
    """Kane's beam on a free hub (120 states: shift-invert, not dense): the hub's rigid motion is a
    double zero of A (a Jordan block Arnoldi converges to only to √ε); the oscillating modes must
    still come out, equal to `rfem modes --free hub` to the linear model's 1e-8 (the first test),
    from LinearModel.modes, rfem.linear.modes and the program's print alike."""
    from rfem import linear
    free = rfem.load(case_path("kane_spinup.toml"), {"joints.0.input": FREE})
    lin = rfem.linearize(free, n=20)
    md = np.asarray(rfem.modes(free, n=20, count=7, free=["hub"]).frequencies)
    assert md[0] == 0.0  # (the hub's rigid turn)
    md = md[1:]
    f = np.array([x[0] for x in lin.modes(6)])
    assert np.abs(f / md - 1).max() < 1e-8, (f, md)
    np.testing.assert_array_equal(linear.modes(lin, 6)[0], f)
