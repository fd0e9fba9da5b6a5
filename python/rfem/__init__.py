"""rfem: dynamics of manipulators with flexible links by the Rigid Finite Element Method.

The same operations as the `rfem` program, from Python, with the same checks and messages:

    import rfem
    case = rfem.load("cases/paper_deployment.toml")          # a case file, checked
    case = case.with_values({"joints.2.input.T": 10.0})        # the paths of `rfem --set`
    runs = rfem.run(case, n=60)                                # rigid, kinematic, force
    u1 = runs["force"].column("tip_deflection", 0)             # numpy, no copy
    print(runs["force"].peaks, runs["force"].stats)

    rfem.static(case), rfem.modes(case, count=6), rfem.refine(case, ns=[6, 12, 24], quantities=["peak:u1"])
    rfem.plot("results.h5")                                    # the figures of `rfem plot`
    rfem.plots.tips(runs["force"])                             # a Figure (Jupyter: inline); ax=, fig=: yours
    rfem.animate("arm.h5", output="arm.gif")                   # `rfem animate`; rfem.animate.frame(…, ax=…)

Errors in a case are `rfem.CaseError` (a ValueError) with the program's one-line message
("FILE:LINE: key: what is wrong"); a results file that cannot be written is `rfem.ResultsError`
(an OSError). An argument of the wrong type is a TypeError, a wrong value a ValueError, one line
naming it ("n: must be a positive integer up to 10000000 (got 0)"); a case argument is an rfem.Case
or a case file's path. Ctrl-C during a run stops it within a step and raises `rfem.RunInterrupted` (a
KeyboardInterrupt) whose `.result` holds the runs so far. Long calls release the GIL.
Units are SI; the results layout is README.md's "Results (HDF5)".
"""
import math as _math
import json as _json
import os as _os
import re as _re

from . import _rfem
from ._rfem import (MAX_RFES, Accuracy, Case, CaseError, LinearModel, Model, ModesResult, ResultsError, Run, RunStatus, StaticResult, Sweep,
                    __version__, build)


# The shipped cases (the checkout's cases/*.toml and their URDF files, in the package's cases/): a
# case argument that names one ("kane_spinup") where no such file is finds it, wherever the package is.
_CASES_DIR = _os.path.join(_os.path.dirname(_os.path.abspath(__file__)), "cases")
cases = sorted(f[:-5] for f in _os.listdir(_CASES_DIR) if f.endswith(".toml")) if _os.path.isdir(_CASES_DIR) else []


def case_path(name):
    """The path of the shipped case `name` ("kane_spinup" or "kane_spinup.toml"; rfem.cases lists them)."""
    base = name[:-5] if isinstance(name, str) and name.endswith(".toml") else name
    if base not in cases:
        raise CaseError(f"{name}: no shipped case of that name (rfem.cases: {', '.join(cases)})")
    return _os.path.join(_CASES_DIR, base + ".toml")


def _case(case):
    """A case argument with a shipped case's name (no such file here, no folder in it) as its path."""
    if isinstance(case, (str, _os.PathLike)) and not isinstance(case, Case):
        text = _os.fspath(case)
        # (a name: letters, digits, _ . -; anything else goes to the module's own checks of a path)
        if isinstance(text, str) and _re.fullmatch(r"[A-Za-z0-9_.-]+", text) and not _os.path.exists(text):
            base = text[:-5] if text.endswith(".toml") else text
            if base in cases:
                return case_path(base)
            raise CaseError(f"{text}: cannot open case file, and no shipped case has that name (rfem.cases: {', '.join(cases)})")
    return case


# The compiled functions wrapped in Python ones: a pool pickles a function by its module and name,
# which pybind11's own functions do not have.
def run_point(sweep, k, threads=1):
    return _rfem.run_point(sweep, k, threads)


def finished_point(sweep, k):
    return _rfem.finished_point(sweep, k)


def write_index(sweep, rows):
    return _rfem.write_index(sweep, rows)


def write_xdmf(results, runs=()):
    return _rfem.write_xdmf(results, runs)


# A forked child (multiprocessing's default start on Linux) runs one thread: GNU OpenMP's thread pool
# does not survive fork, and a team there would wait forever (threads > 1 is refused there).
_os.register_at_fork(after_in_child=_rfem._after_fork)

for _f in (run_point, finished_point, write_index, write_xdmf):
    _f.__doc__ = getattr(_rfem, _f.__name__).__doc__.split("\n", 1)[-1].strip()

__all__ = ["Accuracy", "Case", "CaseError", "cases", "case_path", "Frame", "LinearModel", "linearize", "Model", "ModesResult", "ResultsError", "Run", "RunInterrupted", "RunStatus", "Runs",
           "StaticResult", "RefineResult", "Tree", "load", "model", "show", "run", "static", "modes", "refine", "plot",
           "write_xdmf", "animate", "toml_value", "__version__", "Sweep", "SweepResult", "load_sweep", "sweep", "run_point",
           "finished_point", "write_index"]


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C (or an exception in a progress callback) stopped a study. `.result` holds what was
    done: the runs so far (a Runs; the interrupted one with status "interrupted (signal 2)" and
    every output up to the stop), or a RefineResult with the rows done."""

    def __init__(self, result, message="interrupted"):
        super().__init__(message)
        self.result = result


def toml_value(value):
    """A Python value as a TOML literal (for Case.with_values): bool, int, float (inf, nan),
    str, lists and dicts of these."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if _math.isnan(value):
            return "nan"
        if _math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return _json.dumps(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {toml_value(v)}" for k, v in value.items()) + "}"
    if hasattr(value, "tolist"):  # numpy scalars and arrays
        return toml_value(value.tolist())
    raise TypeError(f"cannot write {type(value).__name__} as a TOML value")


def _with_values(self, values):
    """The case with new values at the paths of `rfem --set` ({"links.0.n": 48,
    "joints.2.input.T": 10.0, "simulation.procedure": "single"}), read and checked again: a bad
    value raises CaseError naming the key."""
    return self.with_overrides([f"{k}={toml_value(v)}" for k, v in values.items()])


Case.with_values = _with_values


class Frame(dict):
    """One series of a run by column name ({"u1": array, …}, a row per output) with .units
    {column: unit}, .name and .description, as in the results file (Run.frame)."""

    name = ""
    description = ""
    units = {}

    def __repr__(self):
        cols = ", ".join(f"{c} [{u}]" if u else c for c, u in self.units.items())
        rows = len(next(iter(self.values()))) if self else 0
        return f"<rfem.Frame {self.name}: {rows} rows; {cols}>"


def _frame(self, name):
    """Series `name` by column name: a Frame {column: read-only 1-D array} with .units."""
    info = self.info(name)
    table = self.table(name)
    f = Frame((c, table[:, k]) for k, c in enumerate(info["columns"]))
    f.name, f.description, f.units = info["name"], info["description"], dict(zip(info["columns"], info["units"]))
    return f


Run.frame = _frame


def _accuracy_texts(accuracy):
    """accuracy= as the program's --accuracy texts: 1e-3 (relative), "peak:u1=2e-4",
    {"peak:u1": 2e-4}, or a list of these."""
    if accuracy is None:
        return None
    if isinstance(accuracy, bool):
        raise TypeError("accuracy: a relative error (1e-3), 'QUANTITY=ERROR', {QUANTITY: ERROR} or a list of these, not bool")
    if isinstance(accuracy, (int, float)):
        return [repr(float(accuracy))]
    if isinstance(accuracy, str):
        return [accuracy]
    if isinstance(accuracy, dict):
        return [f"{q}={_accuracy_texts(e)[0]}" for q, e in accuracy.items()]
    if isinstance(accuracy, (list, tuple)):
        return [t for a in accuracy for t in _accuracy_texts(a)]
    raise TypeError("accuracy: a relative error (1e-3), 'QUANTITY=ERROR', {QUANTITY: ERROR} or a list of these, "
                    f"not {type(accuracy).__name__}")


def _target(case, command, accuracy, max_n, n, count=6, rate=None, joint=1, threads=0, progress=None, max_time=None,
            free=None):
    """The Accuracy a target asks for (accuracy=, or the case's [accuracy] without n), or None."""
    case = _case(case)
    acc, error = _rfem._accuracy(case, command, _accuracy_texts(accuracy), max_n, max_time, n, count, rate, joint, threads,
                                 progress, free)
    _raise(error, acc)
    return acc


def load(path, values=None, overrides=()):
    """Reads and checks a case file (TOML), by its path or by the name of a shipped case
    ("kane_spinup": rfem.cases). `values`: {path: value} as in Case.with_values; `overrides`:
    'key.path=value' strings as given to `rfem --set`."""
    case = Case.load(_case(path), overrides)
    return case.with_values(values) if values else case


def model(case, n=None):
    """The case's Model with n rfes in all links (None: the case's own discretisation)."""
    case = _case(case)
    return _rfem.model(case, n)


class Runs(list):
    """The runs of a study in order (a list of Run), also by name: runs["force"]."""

    def __getitem__(self, key):
        if isinstance(key, str):
            for r in self:
                if r.name == key or r.name.endswith("/" + key):
                    return r
            raise KeyError(f"no run named {key!r} (have {[r.name for r in self]})")
        return super().__getitem__(key)

    @property
    def completed(self):
        return all(r.completed for r in self)

    warnings = ()
    kept = ()
    accuracy = None  # rfem.Accuracy with accuracy= (each peak with its error bar)

    def __repr__(self):
        return "<rfem.Runs " + ", ".join(f"{r.name}: {r.status}" for r in self) + ">"


def run(case=None, n=None, output=None, runs=None, threads=0, keep_series=True, progress=None, resume=None,
        checkpoint=_rfem.CHECKPOINT_INTERVAL, controller=None, sample_time=None, delay=0, accuracy=None, max_n=None,
        max_time=None, reduction_check=True):
    """Runs the case's [simulation] by its procedure (single: "run"; paper: "rigid", "kinematic",
    "force") and returns the Runs.

    controller:  f(t, y) in the loop at t = k * sample_time [s], its outputs held (zero-order hold)
                 `delay` samples later: rfem.run_controlled (one run, "run"; no runs, progress, resume
                 or checkpoint with it)

    n:           rfes in all links (None: the case's own)
    output:      an HDF5 results file written while the runs go (the layout of `rfem run`), and
                 beside it ParaView's view of each run when the case stores poses
                 (simulation.store_flexible_every > 0), as `rfem run` writes them
    runs:        a subset of the procedure's run names, e.g. ["rigid", "kinematic"]
    threads:     kernel threads (0: each run times one thread against all)
    keep_series: keep every series in memory (Run.table, Run.column); False keeps only summaries
    progress:    called about ten times a second with {"run", "t", "t_end", "steps"}
    resume:      a results file an interrupted or killed run left (rfem.run with output=, or rfem run):
                 continue its runs from their last checkpoints, as `rfem run --resume` (no case, n,
                 output or runs: the file has them); returns the runs run now (.kept: the names of
                 those that had completed), their series read back whole from the file
    checkpoint:  seconds of wall time between checkpoints written into `output` (0: none)
    accuracy:    a target instead of n (`rfem run --accuracy`; the case's [accuracy] applies without
                 n): 1e-3 (relative to each peak's scale), "peak:force/u1=2e-4" or {"peak:u1": 2e-4}
                 (absolute), or a list; rfem chooses the tolerances and n (up to max_n, default 2048;
                 max_time: seconds the ladder may take, it stops before an n predicted to end past it)
                 and the Runs carry .accuracy (rfem.Accuracy: each peak with its error bar; .met)

    A case with reduced links (links.modes) runs its procedure again on the full and the reduced
    model at a coarse n: each Run's .reduction_error is the estimate of its peaks' reduction error
    (README, "Reduced links"), and a warning says where it exceeds the target (or 1e-4 of a peak);
    reduction_check=False skips those runs (`rfem run --no-reduction-check`).

    A run that fails has status "failed: …" (the outputs before kept); Ctrl-C raises
    RunInterrupted with the runs so far in .result."""
    case = _case(case)
    if resume is not None:
        if case is not None or n is not None or output is not None or runs is not None:
            raise ValueError("rfem.run(resume=...) takes no case, n, output or runs: the results file has them")
        out, error, warnings, kept = _rfem._resume(resume, threads, keep_series, progress, checkpoint)
        result = Runs(out)
        result.warnings = warnings
        result.kept = kept
        _raise(error, result)
        return result
    if case is None:
        raise ValueError("rfem.run needs a case (or resume=RESULTS.h5)")
    if controller is not None or sample_time is not None:
        if controller is None or sample_time is None:
            raise ValueError("rfem.run: a controller needs its sample_time, and a sample_time a controller")
        if runs is not None or progress is not None:
            raise ValueError("rfem.run(controller=...) is one run: no runs or progress with it")
        result = Runs([run_controlled(case, controller, sample_time, n=n, delay=delay, output=output, threads=threads,
                                      keep_series=keep_series)])
        return result
    acc = _target(case, "run", accuracy, max_n, n, threads=threads, progress=progress, max_time=max_time)
    if acc is not None:
        if runs is not None:
            raise ValueError("rfem.run(accuracy=...) runs the whole procedure: no runs with it")
        case = (case if isinstance(case, Case) else load(case)).with_values({"simulation.rtol": acc.rtol,
                                                                              "simulation.atol": acc.atol})
        n = acc.n
    out, error, warnings = _rfem._run(case, n, output, runs, threads, keep_series, progress, checkpoint,
                                      acc.relative if acc is not None and acc.relative > 0 else None, reduction_check)
    result = Runs(out)
    result.warnings = warnings
    result.accuracy = acc
    _raise(error, result)
    if acc is not None and result.completed:
        _rfem._add_reduction_error(acc, out)
        if output is not None:
            _rfem._write_accuracy(output, acc)
    return result


class Tree(list):
    """The assembled tree of a case (rfem.show): one dict per joint, link and payload — kind, name,
    depth, parent, where (on a link), mass [kg], length [m], rfes, detail (type, axis, input,
    segments), coordinates (which entries of q) — depth first; str() is the text of `rfem show`.
    A URDF base: .urdf (its file) and .frames (one dict per URDF link: name, parent — the joint whose
    body it is welded to, or "ground" — and where on that body)."""

    text = ""
    urdf = ""
    frames = ()

    def __str__(self):
        return self.text

    def __repr__(self):
        return f"<rfem.Tree {len(self)} entries: " + ", ".join(f"{e['kind']} {e['name']}" for e in self[:6]) + \
            (", …" if len(self) > 6 else "") + ">"


def show(case, n=None):
    """What the case builds, to check against its drawing: every joint, link and payload with
    what it is mounted on and where, masses, rfes, coordinates and inputs. print(rfem.show(case))."""
    case = _case(case)
    text, entries, urdf, frames = _rfem._show(case, n)
    tree = Tree(entries)
    tree.text, tree.urdf, tree.frames = text, urdf, frames
    return tree


def static(case, n=None, rate=None, joint=1, accuracy=None, max_n=None, max_time=None):
    """Static equilibrium with the joints held at their values (or turning steadily: `rate`
    [rad/s or m/s] of joint `joint`, from 1) under gravity and the case's tip loads. Returns a
    StaticResult (tips per link, energies, coordinates). accuracy= (as rfem.run's; `rfem static
    --accuracy`): n chosen for the tips' displacements and rotations; .accuracy has their bars."""
    case = _case(case)
    acc = _target(case, "static", accuracy, max_n, n, rate=rate, joint=joint, max_time=max_time)
    result = _rfem._static(case, acc.n if acc is not None else n, rate, joint)
    result.accuracy = acc
    return result


def modes(case, n=None, count=6, free=(), rate=None, joint=1, output=None, accuracy=None, max_n=None, max_time=None):
    """Natural frequencies and mode shapes of the flexible links about the static equilibrium,
    joints held except those in `free` (numbers from 1, names, or "base"), optionally in a frame
    turning at `rate` about joint `joint`. Returns a ModesResult (frequencies [Hz], kinds,
    shapes, exact references for one uniform segment); `output`: an HDF5 file with the
    frequencies and shapes (group modes, as `rfem modes -o`). accuracy= (as rfem.run's; `rfem
    modes --accuracy`): n chosen for the first `count` frequencies; .accuracy has their bars."""
    case = _case(case)
    acc = _target(case, "modes", accuracy, max_n, n, count=count, rate=rate, joint=joint, max_time=max_time, free=free)
    result = _rfem._modes(case, acc.n if acc is not None else n, count, free, rate, joint, output)
    result.accuracy = acc
    if acc is not None and output is not None:
        _rfem._write_accuracy(output, acc)
    return result


class RefineResult(dict):
    """A refinement study: ["status"], ["ns"], and per quantity ["tables"][k] with "quantity",
    "n", "value", "change", "order", "richardson" (arrays), "fitted_order",
    "integration_error", "reference", "warnings" and the error bar of the last value, value[-1]:
    "error" = "error_space" (Roache's grid convergence index) + "error_time" (the integration
    check; 0 for static and modal values), "allowed" (with a target: the bar it asked for), "observed_order" and "asymptotic" (False, and the bar
    NaN, where the series does not show the asymptotic range: no bar rather than a false one);
    table("peak:u1") finds one by name."""

    def table(self, quantity):
        for t in self["tables"]:
            if t["quantity"] == quantity:
                return t
        raise KeyError(quantity)

    def __repr__(self):
        return f"<rfem.RefineResult {self['status']}: n = {list(self['ns'])}, " + \
            ", ".join(f"{t['quantity']} order {t['fitted_order']:.3g}" for t in self["tables"]) + ">"


def refine(case, ns, quantities, output=None, integration_check=True, rate=None, joint=1, threads=0, progress=None,
           modes=None, accuracy=None, max_n=None, max_time=None):
    """Quantities over an increasing series of n with observed orders and Richardson values
    (the quantities of `rfem refine`: "tip:uz", "bending-y:1", "peak:u1", "force/u1@10", …).
    Dynamic quantities share one run per n; `output` keeps every run and the tables in HDF5.
    modes=[4, 8, 16] (`rfem refine --modes`): a series over modes instead, at the one n of `ns`:
    every flexible link reduced to m modes, then the full model; each table's "modes" (0: full),
    "value" and "change" (value − the full model's). accuracy=1e-3 (`rfem refine --accuracy`; also
    "peak:u1=2e-4", {"peak:u1": 2e-4} or a list): an error bar every quantity must meet instead of a
    fixed series: the tolerances chosen for it (["rtol"], ["atol"], ["calibration"]), n doubles from
    the last of `ns` (or 8, with ns=None) until every table's "error" ≤ its "allowed" or the next n
    passes max_n (2048) or, with max_time (seconds), is predicted to end past it (["time_limit"] says
    so); ["met"] says whether it was, ["shortfall"] why not and by how much.
    Ctrl-C raises RunInterrupted with the rows done in .result."""
    case = _case(case)
    out, error = _rfem._refine(case, ns, quantities, output, integration_check, rate, joint, threads, progress, modes,
                               _accuracy_texts(accuracy), max_n, max_time)
    result = RefineResult(out)
    _raise(error, result)
    return result


class SweepResult(dict):
    """A sweep (rfem.sweep): ["parameters"] (names) and ["values"] (points × parameters; NaN where
    a value is not a number), ["quantities"] (names) and ["table"] (points × quantities; NaN where
    a point did not complete), ["status"], ["files"] (each point's results file), ["index"];
    column("peak:u1") is one quantity's column, "n" one parameter's."""

    def column(self, name):
        if name in self["quantities"]:
            return self["table"][:, self["quantities"].index(name)]
        if name in self["parameters"]:
            return self["values"][:, self["parameters"].index(name)]
        raise KeyError(f"no quantity or parameter {name!r} (have {self['quantities'] + self['parameters']})")

    @property
    def completed(self):
        return all(RunStatus.parse(s).completed for s in self["status"])

    warnings = ()

    def __repr__(self):
        done = sum(RunStatus.parse(s).completed for s in self["status"])
        return f"<rfem.SweepResult {len(self['status'])} points ({done} completed) over {self['parameters']}: " \
            f"{self['quantities']}; index {self['index']}>"


def load_sweep(path, output=None):
    """Reads a sweep file and checks every point before anything runs; returns a Sweep (its
    .points: overrides, values, file, cost) for rfem.sweep or for your own scheduler
    (rfem.run_point(sweep, k) in any process or pool, then rfem.write_index(sweep, rows))."""
    return _rfem.load_sweep(path, output)


def sweep(path, output=None, jobs=0, retry_failed=False, progress=None):
    """Runs a sweep file as `rfem sweep` does: every point not already finished in its file,
    longest first, `jobs` at a time (0: the cores), the index rewritten after each. Returns a
    SweepResult. progress: called with {"done", "failed", "running", "total", "left_s"}. Ctrl-C
    stops the running points (they run again next time) and raises RunInterrupted with the rows."""
    s = path if isinstance(path, _rfem.Sweep) else load_sweep(path, output)
    rows, error, warnings = _rfem._sweep(s, jobs, retry_failed, progress)
    import numpy as _np
    result = SweepResult(parameters=list(s.parameters), quantities=list(s.quantities), index=s.index,
                         values=_np.array([p["values"] for p in s.points], dtype=float).reshape(len(s), -1),
                         table=_np.array([r["values"] for r in rows], dtype=float).reshape(len(s), -1),
                         status=[r["status"] for r in rows], files=[p["file"] for p in s.points], rows=rows)
    result.warnings = warnings
    _raise(error, result)
    return result


def plot(results, outdir=None, format="png", paper_signs=False):
    """The figures of `rfem plot` for a results or refinement file (default directory: the
    file's; format png, pdf or svg; paper_signs: u1, u2 with the paper's sign); returns the paths
    written. A file it cannot read raises rfem.plots.PlotError (a RuntimeError) with the program's
    one-line message. To draw onto your own matplotlib Axes (Jupyter: inline): rfem.plots."""
    from . import plots
    return plots.write(results, outdir, format, paper_signs)


def __getattr__(name):
    # rfem.plots and rfem.animate: modules imported when first used (matplotlib and h5py load then).
    # rfem.animate is callable: rfem.animate(results, output=None, run=None, scale=None, view="3d",
    # fps=25, frames=300) writes the film and returns its path (python/rfem/animate.py).
    if name in ("plots", "animate", "linear"):
        import importlib
        return importlib.import_module("." + name, __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | {"plots", "animate", "linear"})


def linearize(case, n=None, state=None, threads=1, equilibrium=True, output=None, dense=False, accuracy=None, max_n=None,
              max_time=None):
    """The case's linear model (an rfem.LinearModel) about its initial state — the static equilibrium
    of simulation.initial = "static" at t = 0 — or about `state` (an rfem.SimulationState: the same
    model, its time), at rest (equilibrium=True: accelerations zero, u0 the torques that hold it) or on
    the motion:

        M q'' + D q' + K q = B u,   y = Cq q + Cv q' + Ca q''   (deviations, SI units)

    over the unknowns (`states`: rfe coordinates and free joints; prescribed joints held on their
    motion, their torque an output), inputs u a torque added at each free joint, outputs every link's
    tip deflection, every joint's q, v, tau and the case's sensors. By central differences of the
    equations the integrators solve (the case's laws, PD gains included): M, D, K, B sparse
    (scipy.sparse) from O(1) evaluations whatever n, checked against the equations' directional
    differences; dense=True differences them column by column (the reference, O(n²)).
    lin.state_space() gives (A, B, C, D) for x = (q, q') (dense, up to 3000 states), lin.modes() the
    lowest modes. `output`: an HDF5 file (group "linear": every matrix with its row and column names,
    M, D, K, B as (row, column, value) tables; MATLAB's h5read, h5py, SciPy read it), as
    `rfem linearize -o`. accuracy= (as rfem.run's; `rfem linearize --accuracy`): n chosen for the six
    lowest frequencies of the model about rest; .accuracy has their bars."""
    case = _case(case)
    if accuracy is not None and state is not None:
        raise CaseError("--accuracy: a saved state has its own n (give no --state, or no target)")
    acc = _target(case, "linearize", accuracy, max_n, n, max_time=max_time) if state is None else None
    lin = _rfem._linearize(case, acc.n if acc is not None else n, state, threads, equilibrium, output,
                           "rfem.linearize (Python)", dense)
    lin.accuracy = acc
    if acc is not None and output is not None:
        _rfem._write_accuracy(output, acc)
    return lin


def _frequency_response(self, frequencies, input=None, output=None):
    """G(j2πf) for f in `frequencies` [Hz] (rfem.linear.frequency_response): complex, shape
    (len f, outputs, inputs), or (len f,) for one named input and output."""
    from .linear import frequency_response
    return frequency_response(self, frequencies, input, output)


LinearModel.frequency_response = _frequency_response


# A simulation a script steps and controllers in the loop (python/rfem/simulation.py).
from .simulation import Simulation, SimulationState, load_state, run_controlled, _raise  # noqa: E402

__all__ += ["Simulation", "SimulationState", "load_state", "run_controlled"]
