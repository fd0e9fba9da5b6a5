"""The Python module against the program: the same library behind both, so the same numbers (bit
for bit with one thread), the same one-line errors, Ctrl-C that keeps what was done, and objects
that stay valid under garbage collection. Run by CTest (label unit) with the build's module:

    PYTHONPATH=build/python RFEM=build/apps/rfem /usr/bin/python3 -m pytest -q tests/python
"""
import gc
import json
import os
import signal
import subprocess

import h5py
import numpy as np
import pytest

import rfem

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RFEM = os.environ.get("RFEM", os.path.join(ROOT, "build", "apps", "rfem"))


def case_path(name):
    return os.path.join(ROOT, "cases", name)


def program(*args, cwd=None):
    p = subprocess.run([RFEM, *args], capture_output=True, text=True, cwd=cwd,
                       env=dict(os.environ, OMP_WAIT_POLICY="PASSIVE"))
    return p.returncode, p.stdout, p.stderr


# The shipped cases, shortened: every kind of input, one and several links, a free base.
RUNS = [("kane_spinup.toml", 12, ["simulation.t_end=2"]),
        ("paper_deployment.toml", 6, ["simulation.t_end=1"]),
        ("two_link_arm.toml", 8, ["simulation.t_end=0.5"]),
        ("space_deployment.toml", 6, ["simulation.t_end=0.5"])]


@pytest.mark.parametrize("name,n,sets", RUNS)
def test_run_equals_program(tmp_path, name, n, sets):
    cli = tmp_path / "cli.h5"
    args = ["--threads", "1", "run", case_path(name), "--n", str(n), "-q", "-o", str(cli)]
    for s in sets:
        args += ["--set", s]
    code, _, err = program(*args)
    assert code == 0, err
    case = rfem.load(case_path(name), overrides=sets)
    py_file = tmp_path / "py.h5"
    runs = rfem.run(case, n=n, threads=1, output=py_file)
    assert runs.completed
    with h5py.File(cli, "r") as f, h5py.File(py_file, "r") as g:
        for r in runs:
            assert f[r.name].attrs["status"] == r.status == "completed"
            assert f[r.name].attrs["steps"] == r.stats["steps"]
            for series in r.names:
                mem = r.table(series)
                # in memory and in the module's file: the program's numbers, bit for bit
                np.testing.assert_array_equal(mem, f[r.name][series][()], err_msg=f"{name} {r.name}/{series}")
                np.testing.assert_array_equal(g[r.name][series][()], f[r.name][series][()])


def test_static_modes_refine_equal_program():
    code, out, err = program("static", case_path("two_link_arm.toml"), "--set", "loads.tip_force=[0,0.5,0]", "--json")
    assert code == 0, err
    js = json.loads(out)
    st = rfem.static(rfem.load(case_path("two_link_arm.toml"), {"loads.tip_force": [0, 0.5, 0]}))
    for link in js["links"]:
        assert list(st.tips[link["name"]]["displacement"]) == link["tip_displacement"]
    assert st.elastic_energy == js["elastic_energy"]
    code, out, err = program("modes", case_path("kane_spinup.toml"), "--free", "hub", "--count", "4", "--json")
    js = json.loads(out)
    md = rfem.modes(rfem.load(case_path("kane_spinup.toml")), count=4, free=["hub"])
    assert [m["frequency_hz"] for m in js["modes"]] == list(md.frequencies)
    assert [m["kind"] for m in js["modes"]] == md.kinds
    # the shapes are M-orthonormal: what modes of a symmetric problem must be
    assert md.shapes.shape == (4, 6 * 40 + 1)
    code, out, err = program("refine", case_path("kane_beam.toml"), "--n", "5,10,20", "--quantity", "bending-y:1,tip:uz",
                             "--json")
    js = json.loads(out)
    ref = rfem.refine(rfem.load(case_path("kane_beam.toml")), ns=[5, 10, 20], quantities=["bending-y:1", "tip:uz"])
    for q in js["quantities"]:
        assert [r["value"] for r in q["rows"]] == list(ref.table(q["quantity"])["value"])
    # the static tip converges with order 2 (docs/formulation.md §7.5)
    assert abs(ref.table("tip:uz")["order"][-1] - 2.0) < 0.05
    # and each table carries its last value's error bar, the program's (docs/accuracy.md)
    for q in js["quantities"]:
        t = ref.table(q["quantity"])
        assert t["asymptotic"] and q["asymptotic"] and t["error"] == q["error"] and t["error_time"] == 0.0
    # An accuracy instead of a series: the program's choice of n and bars; a target that cannot be
    # met up to max_n is not met (exit 3 in the program), with how far it falls short.
    code, out, err = program("refine", case_path("kane_beam.toml"), "--quantity", "mode:1", "--accuracy", "1e-4", "--json")
    js = json.loads(out)
    acc = rfem.refine(rfem.load(case_path("kane_beam.toml")), None, ["mode:1"], accuracy=1e-4)
    assert code == 0 and js["met"] and acc["met"]
    assert [r["n"] for r in js["quantities"][0]["rows"]] == list(acc["ns"]) and acc["ns"][0] == 8
    assert acc["tables"][0]["error"] <= 1e-4 * acc["tables"][0]["value"][-1]
    code, out, err = program("refine", case_path("kane_beam.toml"), "--quantity", "mode:1", "--accuracy", "1e-8", "--max-n", "32")
    assert code == 3 and "NOT met" in out and "n ≈" in out
    short = rfem.refine(rfem.load(case_path("kane_beam.toml")), None, ["mode:1"], accuracy=1e-8, max_n=32)
    assert not short["met"] and len(short["shortfall"]) == 1
    timed = rfem.refine(rfem.load(case_path("kane_beam.toml")), None, ["mode:1"], accuracy=1e-4, max_time=1e-6)
    assert not timed["met"] and list(timed["ns"]) == [8] and "past --max-time" in timed["time_limit"]
    m = rfem.modes(case_path("kane_beam.toml"), count=1, accuracy=1e-4, max_time=1e-6)
    assert not m.accuracy.met and "past --max-time" in m.accuracy.shortfall[0]
    for bad in (0, -1.0, float("nan")):
        with pytest.raises(ValueError):
            rfem.modes(case_path("kane_beam.toml"), accuracy=1e-4, max_time=bad)


def test_accuracy_on_modes_static_and_run(tmp_path):
    """accuracy= on rfem.modes, rfem.static and rfem.run: the program's n, values and bars
    (`--accuracy`), the absolute form as a dict, the same one-line refusals (docs/accuracy.md)."""
    beam = case_path("kane_beam.toml")
    code, out, err = program("modes", beam, "--accuracy", "1e-4", "--count", "3", "--json")
    js = json.loads(out)["accuracy"]
    m = rfem.modes(beam, count=3, accuracy=1e-4)
    assert code == 0 and m.accuracy.met and m.n == js["n"] == m.accuracy.n
    for e, f in zip(js["estimates"], m.accuracy.estimates):
        assert e["quantity"] == f["quantity"] and e["value"] == f["value"] and e["error"] == f["error"]
    assert list(m.frequencies[:3]) == pytest.approx([e["value"] for e in js["estimates"]], rel=1e-12)  # (the modes there)
    s = rfem.static(beam, accuracy={"tip:uz": 1e-6})
    assert s.accuracy["tip:uz"]["error"] <= 1e-6 and s.accuracy["tip:uz"]["allowed"] == 1e-6
    runs = rfem.run(case_path("kane_spinup.toml"), accuracy=1e-3, threads=1, output=tmp_path / "k.h5", keep_series=False)
    u1 = runs.accuracy["peak:run/u1"]
    assert runs.accuracy.met and abs(u1["value"] - 0.5738494557) <= u1["error"] and runs.accuracy.rtol <= 1e-6
    for bad in (-1e-3, 0.0, float("nan"), 1e-12, "peak:nope=1e-3"):
        with pytest.raises(rfem.CaseError) as e:
            rfem.run(case_path("kane_spinup.toml"), accuracy=bad)
        code, _, err = program("run", case_path("kane_spinup.toml"), "--accuracy", repr(bad) if isinstance(bad, float) else bad,
                               "-o", str(tmp_path / "bad.h5"))
        assert code == 2 and err.strip() == "rfem: error: " + str(e.value)
    with pytest.raises(rfem.CaseError):
        rfem.modes(beam, n=16, accuracy=1e-3)
    code, out, err = program("modes", case_path("kane_spinup.toml"), "--free", "hub", "--count", "4", "--accuracy", "1e-4",
                             "--json")
    js = json.loads(out)["accuracy"]
    free = rfem.modes(case_path("kane_spinup.toml"), count=4, free=["hub"], accuracy=1e-4)
    assert code == 0 and free.accuracy.met and free.n == js["n"] and free.accuracy["mode:1"]["zero"]
    assert free.accuracy["mode:3"]["value"] == js["estimates"][2]["value"] == pytest.approx(2.650079, abs=1e-6)
    lin = rfem.linearize(case_path("two_link_arm.toml"), accuracy=1e-3)
    assert lin.accuracy.met and len(lin.accuracy) == 6 and lin.accuracy["linear:1"]["value"] == pytest.approx(
        lin.modes(1)[0][0], rel=1e-9)


@pytest.mark.parametrize("bad", ["14_negative_E.toml", "85_unknown_parent.toml", "51_unknown_input_kind.toml",
                                 "105_urdf_not_xml.toml", "110_urdf_bad_inertia.toml"])
def test_bad_input_same_message(bad):
    path = os.path.join(ROOT, "tests", "bad_cases", bad)
    code, _, err = program("static", path)
    assert code == 2 and err.startswith("rfem: error: ")
    with pytest.raises(rfem.CaseError) as e:
        rfem.load(path)
    assert str(e.value) == err.strip()[len("rfem: error: "):]
    assert isinstance(e.value, ValueError)


def test_case_changed_in_memory(tmp_path):
    case = rfem.load(case_path("kane_spinup.toml"))
    faster = case.with_values({"joints.0.input.Omega": 10, "simulation.t_end": 1.0, "link.n": 8})
    assert case.t_end == 20.0 and faster.t_end == 1.0  # the original is untouched
    code, _, err = program("--threads", "1", "run", case_path("kane_spinup.toml"), "-q", "-o", str(tmp_path / "c.h5"),
                           "--set", "joints.0.input.Omega=10", "--set", "simulation.t_end=1.0", "--set", "link.n=8")
    assert code == 0, err
    r = rfem.run(faster, threads=1)[0]
    with h5py.File(tmp_path / "c.h5", "r") as f:
        np.testing.assert_array_equal(r.table("joint_tau"), f["run/joint_tau"][()])
    # the hub follows Kane's spin-up law to Omega = 10 rad/s (docs/formulation.md §3)
    T = 15.0
    t = r.column("time", 0)
    law = 10.0 / T * (t ** 2 / 2 + (T / (2 * np.pi)) ** 2 * (np.cos(2 * np.pi * t / T) - 1))
    np.testing.assert_allclose(r.column("joint_q", 0), law, rtol=0, atol=1e-12)
    with pytest.raises(rfem.CaseError, match=r"materials\.kane\.E: must be positive"):
        case.with_values({"materials.kane.E": -1.0})
    with pytest.raises(rfem.CaseError, match=r"simulation\.t_ned: unknown key"):
        case.with_values({"simulation.t_ned": 1.0})


def test_ctrl_c_keeps_the_results_and_the_next_run_goes_on(tmp_path):
    case = rfem.load(case_path("paper_deployment.toml"), {"simulation.procedure": "single", "simulation.t_end": 6.0})
    sent = []

    def progress(p):  # Ctrl-C from inside the run, once it is under way: deterministic
        if p["t"] > 1.0 and not sent:
            sent.append(p["t"])
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(rfem.RunInterrupted) as e:
        rfem.run(case, n=60, threads=1, output=tmp_path / "i.h5", progress=progress, checkpoint=1e-9)
    assert isinstance(e.value, KeyboardInterrupt)
    runs = e.value.result
    r = runs[0]
    assert r.status == "interrupted (signal 2)"
    t = r.column("time", 0)
    assert len(t) >= 20 and t[-1] < 6.0
    np.testing.assert_allclose(t, 0.02 * np.arange(len(t)), atol=1e-9)  # every output up to the stop
    with h5py.File(tmp_path / "i.h5", "r") as f:
        assert f["run"].attrs["status"] == "interrupted (signal 2)"
        assert f["run/time"].shape[0] == len(t)
        np.testing.assert_array_equal(f["run/joint_tau"][()], r.table("joint_tau"))
    # A second run in the same process is not stopped by the first's interrupt, and agrees with
    # the interrupted one where neither's end shapes the steps (t ≤ 1 s).
    again = rfem.run(case.with_values({"simulation.t_end": 1.5}), n=60, threads=1)[0]
    assert again.completed
    k = int(np.searchsorted(t, 1.0 + 1e-9))
    np.testing.assert_array_equal(again.table("joint_tau")[:k], r.table("joint_tau")[:k])
    # Resumed from its last checkpoint (one after every step), the run ends as the uninterrupted
    # one, bit for bit (ESDIRK, one thread), its whole series read back from the file.
    with pytest.raises(ValueError, match="takes no case"):
        rfem.run(case, resume=tmp_path / "i.h5")
    resumed = rfem.run(resume=tmp_path / "i.h5", threads=1)
    assert list(resumed.kept) == [] and resumed[0].completed
    whole = rfem.run(case, n=60, threads=1)[0]
    for name in ("time", "joint_tau", "joint_q", "tip_deflection", "energy"):
        np.testing.assert_array_equal(resumed[0].table(name), whole.table(name))
    assert resumed[0].stats["steps"] == whole.stats["steps"]
    with pytest.raises(rfem.CaseError, match="no such results file"):
        rfem.run(resume=tmp_path / "missing.h5")


def test_arrays_outlive_their_run():
    r = rfem.run(rfem.load(case_path("kane_spinup.toml"), {"simulation.t_end": 1.0, "link.n": 6}), threads=1)[0]
    tau = r.column("joint_tau", 0)
    tip = r.table("tip_deflection")
    copy = np.array(tau)
    assert not tau.flags.writeable
    del r
    gc.collect()
    for _ in range(3):  # other allocations reuse freed memory if the buffer were gone
        rfem.run(rfem.load(case_path("kane_spinup.toml"), {"simulation.t_end": 0.5, "link.n": 6}), threads=1)
    np.testing.assert_array_equal(tau, copy)
    assert tip.shape == (21, 3)


def test_help_and_names():
    assert "n:" in rfem.run.__doc__ and "output:" in rfem.run.__doc__
    assert "Ctrl-C" in rfem.__doc__
    assert rfem.__version__ == program("--version")[1].split()[1]
    m = rfem.model(rfem.load(case_path("two_link_arm.toml")), n=16)
    assert (m.n, m.m) == (16, 2) and [l["name"] for l in m.links] == ["upper", "forearm"]


def test_mode_shape_converges_to_the_cantilevers():
    """The first bending mode of Kane's beam (deflection along z) against the Euler–Bernoulli
    cantilever's shape at the rfe centres, w ∝ cosh βx − cos βx − σ (sinh βx − sin βx), normalised at
    the tip: its error falls at least as 1/n² (measured 4.3 and 5.4 per halving; docs/formulation.md
    §7.6). The file `rfem.modes(output=…)` writes holds the same shapes and kinds."""
    case = rfem.load(case_path("kane_beam.toml"))
    bl, L = 1.875104068711961, 10.0
    sigma = (np.cosh(bl) + np.cos(bl)) / (np.sinh(bl) + np.sin(bl))
    errors = []
    for n in (10, 20, 40):
        md = rfem.modes(case, n=n, count=2)
        z = md.shapes[md.kinds.index("bending-z"), 2::6]  # a row per mode: x3 of every rfe
        lo = (np.arange(n) + 0.5) * L / n  # rfe k spans from sde k to sde k+1 (the last to the tip)
        x = 0.5 * (lo + np.append(lo[1:], L))
        w = np.cosh(bl * x / L) - np.cos(bl * x / L) - sigma * (np.sinh(bl * x / L) - np.sin(bl * x / L))
        errors.append(np.abs(z / z[-1] - w / w[-1]).max())
    assert errors[0] < 1e-3
    assert errors[0] / errors[1] > 3.5 and errors[1] / errors[2] > 3.5
    path = os.path.join(os.environ.get("TMPDIR", "/tmp"), "rfem_modes_test_%d.h5" % os.getpid())
    out = rfem.modes(case, n=20, count=2, output=path)
    with h5py.File(path, "r") as f:
        np.testing.assert_array_equal(f["modes/shapes"][()], out.shapes)  # one convention: a row per mode
        assert list(f["modes"].attrs["kinds"]) == [f"{k}{i}" for k, i in zip(out.kinds, out.index_of_kind)]
    os.remove(path)


def test_show_and_differences():
    tree = rfem.show(rfem.load(case_path("two_link_arm.toml")))
    parents = {e["name"]: e["parent"] for e in tree}
    assert parents == {"shoulder": "ground", "upper": "shoulder", "elbow": "upper", "forearm": "elbow",
                       "forearm.payload1": "forearm"}
    assert "joint elbow — on upper, tip (1 m)" in str(tree)
    case = rfem.load(case_path("paper_deployment.toml"), {"simulation.t_end": 4.0})
    ref = rfem.refine(case, ns=[6, 12], quantities=["peak:kinematic/tau3-rigid/tau3"], integration_check=False, threads=1)
    runs = rfem.run(case, n=12, runs=["rigid", "kinematic"], threads=1)
    d = np.abs(runs["kinematic"].column("joint_tau", 2) - runs["rigid"].column("joint_tau", 2)).max()
    assert ref.table("peak:kinematic/tau3-rigid/tau3")["value"][-1] == d


def test_urdf_arm_from_python(tmp_path):
    """A URDF base from the module: the frames it built, and a run whose file, ParaView view
    included, is the program's."""
    sets = ["simulation.t_end=0.2", "simulation.store_flexible_every=5"]
    case = rfem.load(case_path("urdf_arm.toml"), overrides=sets)
    tree = rfem.show(case)
    assert tree.urdf.endswith("three_link_arm.urdf")
    frames = {f["name"]: (f["parent"], f["where"]) for f in tree.frames}
    assert frames["tool0"] == ("elbow", "at (0.2, 0, 0) m") and frames["base_link"] == ("ground", "")
    run = rfem.run(case, output=tmp_path / "py.h5", threads=1)
    assert run[0].completed and (tmp_path / "py.run.xdmf").exists()
    code, _, err = program("run", case_path("urdf_arm.toml"), "-q", "--threads", "1", "-o", str(tmp_path / "cli.h5"),
                           *[a for s in sets for a in ("--set", s)])
    assert code == 0, err
    a, b = h5py.File(tmp_path / "py.h5"), h5py.File(tmp_path / "cli.h5")
    for name in ("joint_tau", "tip_deflection", "links/tube/axis_rotation"):
        assert np.array_equal(a["run/" + name][()], b["run/" + name][()]), name


def test_sweep_from_python_and_own_pool(tmp_path):
    """rfem.sweep gives the program's table; the building blocks run the points in a user's own
    loop (any pool) into the same index; a bad sweep raises the program's message."""
    sweep = tmp_path / "s.toml"
    sweep.write_text(f'[sweep]\ncase = "{case_path("kane_spinup.toml")}"\nquantities = ["peak:u1"]\n'
                     'set = ["simulation.t_end=2"]\n[parameters]\nn = [4, 8]\n"joints.0.input.T" = [10.0, 15.0]\n')
    code, _, err = program("sweep", str(sweep), "-q", "-o", str(tmp_path / "cli.h5"))
    assert code == 0, err
    r = rfem.sweep(sweep, output=tmp_path / "py.h5", jobs=2)
    assert r.completed and r["parameters"] == ["joints.0.input.T", "n"]
    assert np.array_equal(r["table"], h5py.File(tmp_path / "cli.h5")["quantities"][()])
    s = rfem.load_sweep(sweep, output=tmp_path / "own.h5")
    rows = [rfem.run_point(s, k) for k in range(len(s))]
    with pytest.raises(ValueError, match=r"^k: must be a point of the sweep, 0 to 3 \(got 4\)$"):
        rfem.run_point(s, 4)
    with pytest.raises(TypeError, match=r'^rows\[1\]\["values"\]: must be a list of numbers'):
        rfem.write_index(s, rows[:1] + [dict(rows[1], values="x")] + rows[2:])
    rfem.write_index(s, rows)
    assert np.array_equal(h5py.File(tmp_path / "own.h5")["quantities"][()], r["table"])
    assert rfem.finished_point(s, 0)["status"] == "completed"
    sweep.write_text(sweep.read_text().replace("quantities", "quantity"))
    code, _, err = program("sweep", str(sweep))
    with pytest.raises(rfem.CaseError) as e:
        rfem.load_sweep(sweep)
    assert code == 2 and str(e.value) == err.strip()[len("rfem: error: "):]


NAN = float("nan")
BAD_ARGUMENTS = [  # (call, exception, the message's start: the argument named, as the program names its options)
    (lambda c: rfem.run("/no/such.toml"), rfem.CaseError, "/no/such.toml: "),
    (lambda c: rfem.run(c, n=4.5), TypeError, "n: must be an integer"),
    (lambda c: rfem.run(c, n=NAN), TypeError, "n: must be an integer"),
    (lambda c: rfem.run(c, n=True), TypeError, "n: must be an integer"),
    (lambda c: rfem.run(c, n=10**12), ValueError, "n: must be a positive integer up to 10000000"),
    (lambda c: rfem.run(c, n=rfem.MAX_RFES + 1), ValueError, "n: must be a positive integer up to 10000000"),
    (lambda c: rfem.run(c, n=0), ValueError, "n: "),
    (lambda c: rfem.run(c, n=-1), ValueError, "n: "),
    (lambda c: rfem.run(c, n=4, threads=-1), ValueError, "threads: "),
    (lambda c: rfem.run(c, n=4, threads="2"), TypeError, "threads: "),
    (lambda c: rfem.run(c, n=4, checkpoint=NAN), ValueError, "checkpoint: "),
    (lambda c: rfem.run(c, n=4, checkpoint=-1.0), ValueError, "checkpoint: "),
    (lambda c: rfem.run(c, n=4, runs=[1]), TypeError, "runs[0]: "),
    (lambda c: rfem.run(c, n=4, output="a\0b.h5"), ValueError, "output: "),
    (lambda c: rfem.run(c, n=4, progress=3), TypeError, "progress: "),
    (lambda c: rfem.run(c, n=4, keep_series="yes"), TypeError, "keep_series: "),
    (lambda c: rfem.run(resume=3), TypeError, "resume: "),
    (lambda c: rfem.refine(c, ns=[4, 10**9], quantities=["forearm/peak:u1"]), ValueError, "ns[1]: "),
    (lambda c: rfem.refine(c, ns=4, quantities=["forearm/peak:u1"]), TypeError, "ns: "),
    (lambda c: rfem.modes(c, rate=NAN), ValueError, "rate: "),
    (lambda c: rfem.modes(c, count=0), ValueError, "count: "),
    (lambda c: rfem.modes(c, joint=1.0, rate=1.0), TypeError, "joint: "),
    (lambda c: rfem.modes(c, free=[1.5]), TypeError, "free[0]: "),
    (lambda c: rfem.static(c, rate="1"), TypeError, "rate: "),
    (lambda c: rfem.show(c, n=0), ValueError, "n: "),
    (lambda c: rfem.model(c, n=-1), ValueError, "n: "),
    (lambda c: rfem.load("a\0b"), ValueError, "path: "),
    (lambda c: rfem.load(3), TypeError, "path: "),
    (lambda c: rfem.Case.from_text(3), TypeError, "text: "),
    (lambda c: rfem.write_xdmf("a\0b.h5"), ValueError, "results: "),
    (lambda c: rfem.run_point("s.toml", 0), TypeError, "sweep: "),
    (lambda c: rfem.Simulation(c, n=0), ValueError, "n: "),
    (lambda c: rfem.Simulation(c, n=4).advance(NAN), ValueError, "t: "),
]


@pytest.mark.parametrize("k", range(len(BAD_ARGUMENTS)))
def test_bad_arguments_one_line(k):
    """Every wrong argument is a TypeError (type) or ValueError (value; CaseError is one) with a line
    naming it — never pybind11's overload dump, an overflow, a MemoryError, or accepted."""
    call, error, start = BAD_ARGUMENTS[k]
    case = rfem.load(case_path("two_link_arm.toml"), {"simulation.t_end": 0.1})
    with pytest.raises(error) as e:
        call(case)
    message = str(e.value)
    assert type(e.value) is error and "\n" not in message and message.startswith(start), message


def test_run_status_from_the_library():
    s = rfem.RunStatus.parse("interrupted (signal 2)")
    assert (s.kind, s.signal, s.completed, str(s)) == ("interrupted", 2, False, "interrupted (signal 2)")
    assert rfem.RunStatus.parse("completed").completed and rfem.RunStatus.parse("failed: why").reason == "why"


def test_every_integrator_and_linear_solver_give_the_paper_cases_answer():
    """[simulation] integrator × linear_solver on the paper's deployment (kinematic and force input,
    n = 24, 5 s): the chain solver and CHOLMOD solve the same Newton systems, so with one integrator
    they differ only where round-off moves a step, by less than the integration error the defaults
    keep (1e-4 of every series, cases/paper_deployment.toml; ESDIRK measured 1.3e-7 of the peak);
    ESDIRK and BDF each meet the tolerance their own way and agree within 1e-3 of the peak,
    the accuracy the paper's figures need (BDF's distance from ESDIRK at the same rtol measured here:
    1.3e-4 of the peak)."""
    base = rfem.load(case_path("paper_deployment.toml"), {"simulation.t_end": 5.0})
    out = {}
    for integrator in ("esdirk", "bdf"):
        for solver in ("chain", "cholmod"):
            case = base.with_values({"simulation.integrator": integrator, "simulation.linear_solver": solver})
            out[integrator, solver] = rfem.run(case, n=24, threads=1, runs=["kinematic", "force"])
            assert out[integrator, solver].completed
    ref = out["esdirk", "chain"]
    for (integrator, solver), runs in out.items():
        for name in ("kinematic", "force"):
            a, b = ref[name].table("tip_deflection"), runs[name].table("tip_deflection")
            rel = (np.abs(a - b).max(axis=0) / np.abs(a).max(axis=0)).max()
            assert rel <= (1e-4 if integrator == "esdirk" else 1e-3), (integrator, solver, name, rel)
    with pytest.raises(rfem.CaseError, match=r'simulation\.linear_solver: must be "chain" or "cholmod" \(got "lu"\)'):
        base.with_values({"simulation.linear_solver": "lu"})


def test_shipped_cases_load_by_name_from_any_folder(tmp_path, monkeypatch):
    """rfem.cases lists the shipped cases (the checkout's cases/*.toml, in the package); a case
    argument that names one where no such file is loads it, its URDF beside it; the same case as its
    path; an unknown name is one CaseError line that lists them."""
    monkeypatch.chdir(tmp_path)
    assert {"kane_spinup", "paper_deployment", "urdf_arm"} <= set(rfem.cases)
    by_name = rfem.load("kane_beam")
    by_path = rfem.load(os.path.join(ROOT, "cases", "kane_beam.toml"))
    assert by_name.name == by_path.name == "kane_beam"
    f = rfem.modes("kane_beam", n=8, count=2).frequencies
    assert list(f) == list(rfem.modes(by_path, n=8, count=2).frequencies)
    assert rfem.load("urdf_arm.toml").name == "urdf_arm"
    with pytest.raises(rfem.CaseError, match=r"^kane_spin: cannot open case file, and no shipped case has that name \(rfem.cases: kane_beam"):
        rfem.load("kane_spin")
