"""rfem's objects in process pools: a Case, Model, Run, RunStatus and Sweep survive pickle (and
deepcopy) unchanged, and work handed to multiprocessing and concurrent.futures pools (spawned
processes, so nothing is inherited: everything crosses as a pickle) gives the in-process results bit
for bit (one thread each: the same arithmetic in the same order)."""
import concurrent.futures
import copy
import functools
import multiprocessing
import os
import pickle

import numpy as np
import pytest

import rfem

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def case_path(name):
    return os.path.join(ROOT, "cases", name)


def same_run(a, b):
    assert (a.name, a.status, a.outputs, a.t_reached, a.stats, a.peaks, a.warnings) == \
        (b.name, b.status, b.outputs, b.t_reached, b.stats, b.peaks, b.warnings)
    assert a.names == b.names and a.names
    for name in a.names:
        assert np.array_equal(a.table(name), b.table(name)), name
    assert np.array_equal(a.sensors, b.sensors) and a.sensor_columns == b.sensor_columns


def test_pickle_round_trips(tmp_path):
    case = rfem.load(case_path("two_link_arm.toml"), {"simulation.t_end": 0.3})
    for c in (pickle.loads(pickle.dumps(case)), copy.deepcopy(case)):
        assert (c.path, c.text, c.overrides, c.effective_text) == (case.path, case.text, case.overrides, case.effective_text)
    model = rfem.model(case, 5)
    m = pickle.loads(pickle.dumps(model))
    assert (m.n, m.m, m.dof, m.links, m.joints) == (model.n, model.m, model.dof, model.links, model.joints)
    runs = rfem.run(case, n=5, threads=1)
    back = pickle.loads(pickle.dumps(runs))
    assert isinstance(back, rfem.Runs) and back.warnings == runs.warnings
    for a, b in zip(runs, back):
        same_run(a, b)
        assert b.model.n == a.model.n
    assert np.array_equal(back["run"].frame("tip_deflection")["u1"], runs["run"].column("tip_deflection", "u1"))
    status = rfem.RunStatus.parse("failed: Newton did not converge")
    assert str(pickle.loads(pickle.dumps(status))) == str(status)
    sweep = tmp_path / "s.toml"
    sweep.write_text(f'[sweep]\ncase = "{case_path("kane_spinup.toml")}"\nquantities = ["peak:u1"]\n'
                     '[parameters]\nn = [4, 8]\n')
    s = rfem.load_sweep(sweep, output=tmp_path / "i.h5")
    s2 = pickle.loads(pickle.dumps(s))
    assert s2.points == s.points and s2.parameters == s.parameters
    blob = pickle.dumps(s)
    sweep.write_text(sweep.read_text().replace("[4, 8]", "[4, 9]"))
    with pytest.raises(ValueError, match="changed since this Sweep was pickled"):
        pickle.loads(blob)


def test_a_pool_of_runs_and_a_pool_sweep_equal_the_in_process_ones(tmp_path):
    """multiprocessing.Pool runs three gains of a case (Case in, Runs out); a ProcessPoolExecutor
    runs a sweep's points (Sweep in, rows out) into the index rfem.sweep writes: equal bit for bit."""
    base = rfem.load(case_path("kane_spinup.toml"), {"simulation.t_end": 1.0})
    cases = [base.with_values({"joints.0.input.T": T}) for T in (10.0, 12.5, 15.0)]
    run = functools.partial(rfem.run, n=6, threads=1)
    spawn = multiprocessing.get_context("spawn")
    with spawn.Pool(2) as pool:
        pooled = pool.map(run, cases)
    for c, p in zip(cases, pooled):
        same_run(run(c)[0], p[0])
    assert len({next(iter(p[0].peaks.values()))["u1"] for p in pooled}) == 3  # three different answers came back

    sweep = tmp_path / "s.toml"
    sweep.write_text(f'[sweep]\ncase = "{case_path("kane_spinup.toml")}"\nquantities = ["peak:u1", "u1@1"]\n'
                     'set = ["simulation.t_end=1"]\n[parameters]\nn = [4, 6]\n"joints.0.input.T" = [10.0, 15.0]\n')
    reference = rfem.sweep(sweep, output=tmp_path / "ref.h5", jobs=1)
    s = rfem.load_sweep(sweep, output=tmp_path / "pool.h5")
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=spawn) as ex:
        rows = list(ex.map(rfem.run_point, [s] * len(s), range(len(s))))
    rfem.write_index(s, rows)
    assert all(r["status"] == "completed" for r in rows)
    table = np.array([r["values"] for r in rows])
    assert np.array_equal(table, reference["table"]) and np.isfinite(table).all()


def test_a_forked_pool_after_threads_runs_one_thread_each():
    """multiprocessing's default on Linux forks; GNU OpenMP's threads do not survive fork, so a team
    in the child would wait forever. After the parent has run a team of two (n = 300 ≥ the 256 rfes
    from which the kernels use a team), forked workers run with one thread (bit for bit the
    parent's one-thread run) and refuse threads=2 with one line."""
    case = rfem.load(case_path("kane_spinup.toml"), {"simulation.t_end": 0.05})
    two = rfem.run(case, n=300, threads=2)[0]
    one = rfem.run(case, n=300, threads=1)[0]
    assert two.completed and np.array_equal(two.table("tip_deflection"), one.table("tip_deflection"))
    with multiprocessing.get_context("fork").Pool(2) as pool:
        forked = pool.map(functools.partial(rfem.run, n=300), [case, case])
        with pytest.raises(ValueError, match=r"^threads: must be 0 or 1 in a process forked from one that imported rfem"):
            pool.map(functools.partial(rfem.run, n=300, threads=2), [case])
    for r in forked:
        same_run(one, r[0])
