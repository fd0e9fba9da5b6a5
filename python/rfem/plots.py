"""rfem.plots: the figures of `rfem plot`, from a results file or from runs in memory.

From Python (in Jupyter the Figure a function returns shows inline):

    import rfem, rfem.plots as plots
    runs = rfem.run(rfem.load("cases/paper_deployment.toml"), n=6)
    plots.tips(runs["force"])                        # a new Figure: u1, u2, θ against t
    plots.tip(runs["force"], "u1", ax=ax)            # onto your own Axes (returns ax.figure)
    plots.paper_figure(runs, 6)                      # the paper's Figure 6 (5 to 8)
    plots.refinement(rfem.refine(case, ns=[4, 8, 16], quantities=["force/peak:u1"]))
    plots.read("results.h5")["force"]                # a run group of a file, for the same functions
    plots.write("results.h5", "figs")                # every figure of `rfem plot` (rfem.plot); the paths

Functions that draw one panel take `ax=` (a matplotlib Axes); those that draw several take `fig=`
(an empty Figure or SubFigure to fill). Without them they make a Figure (not one of pyplot's: show
it with display(fig) or as a cell's value, save it with fig.savefig). A run is an rfem.Run (from
rfem.run), a Run of this module (plots.read, plots.Run(group)) or a results file's path (its last run,
or run=NAME).

From the shell (what `rfem plot` runs, with Debian's python3-matplotlib, python3-h5py, python3-numpy):

    /usr/bin/python3 -m rfem.plots RESULT.h5 [-o OUTDIR] [--format png|pdf|svg] [--paper-signs]

Writes figures (PNG by default) into OUTDIR (default: the directory of RESULT.h5):
  * for every run group G: G_joints.png, G_tip.png, G_energy.png, and G_momentum.png on a free
    base (linear and angular momentum: constant without gravity);
  * for procedure "paper": fig5_tip.png, fig6_torque3.png, fig7_velocity3.png, fig8_accel12.png
    (the layout of the paper's Figures 5-8);
  * for a file with a `refine` group: refine_convergence.png (and refine_convergence_qK.png for
    every further quantity K);
  * for a sweep's index: sweep_Q_vs_P.png for each quantity Q and parameter P.
"""
import argparse
import os
import re
import sys
import textwrap

import h5py
import numpy as np

__all__ = ["PlotError", "Run", "read", "new_figure", "joint", "joints", "tip", "tips", "energy", "momentum",
           "paper_figure", "refinement", "write", "main"]

DPI = 120
FORMATS = ("png", "pdf", "svg")
SERIES = ["joint_q", "joint_v", "joint_a", "joint_tau", "tip_deflection", "energy", "momentum"]
TIP_LABELS = [("u1", "u1 [m]"), ("u2", "u2 [m]"), ("theta", "θ [rad]")]
ENERGY_LABELS = ["kinetic", "elastic", "gravity", "input work", "dissipated"]
ENERGY_STYLES = ["-", "-", "-", "--", ":"]
UNITS = {"revolute": ("rad", "rad/s", "N m"), "prismatic": ("m", "m/s", "N")}
JOINT_KEYS = ("joint_q", "joint_v", "joint_tau")


class PlotError(RuntimeError):
    """A file `rfem plot` cannot draw: the program's one-line message ("FILE: reason")."""


def text_attr(obj, name, default=""):
    """A string attribute as str (h5py returns fixed-length strings as bytes)."""
    value = obj.attrs.get(name, default)
    if isinstance(value, np.ndarray) and value.size == 1:
        value = value.item()
    return value.decode("utf-8", "replace") if isinstance(value, bytes) else str(value)


def wrap(text):
    return textwrap.fill(text, 75)


def list_attr(obj, name):
    """An array-of-strings attribute as a list of str."""
    value = obj.attrs.get(name)
    if value is None:
        return []
    if isinstance(value, (str, bytes)):
        value = [value]
    return [v.decode("utf-8", "replace") if isinstance(v, bytes) else str(v) for v in np.asarray(value).ravel()]


class Run:
    """The series of one run, read into memory: from a run group of a results file (h5py.Group) or
    from an rfem.Run of rfem.run (kept series). .name, .case, .status, .n, .t, .data (series by
    name), .joints, .types, .tips ([(link, u1 u2 θ table)])."""

    def __init__(self, source, name=None, case=""):
        self.case = case
        if isinstance(source, h5py.Group):
            self._from_group(source, name or source.name.strip("/").split("/")[-1])
        elif hasattr(source, "table") and hasattr(source, "names"):
            self._from_run(source, name)
        else:
            raise TypeError("run: an rfem.Run, an h5py run group or a results file's path (got %s)"
                            % type(source).__name__)

    def _from_group(self, group, name):
        self.name = name
        self.status = text_attr(group, "status", "unknown")
        self.n = int(np.asarray(group.attrs.get("n", -1)).ravel()[0])
        self.t = group["time"][:, 0]
        self.data = {key: np.asarray(group[key][:]) for key in SERIES
                     if key in group and group[key].ndim == 2
                     and group[key].shape[0] == len(self.t)}
        ncols = self.data["joint_q"].shape[1] if "joint_q" in self.data else 0
        self.joints = list_attr(group, "joint_names")
        if len(self.joints) != ncols:
            self.joints = ["joint %d" % (j + 1) for j in range(ncols)]
        self.types = list_attr(group, "joint_types")
        if len(self.types) != ncols:
            self.types = ["revolute"] * ncols
        # Tip deflections of every link (links/NAME/tip_deflection), or of the one link.
        self.tips = []
        names = list_attr(group, "link_names")
        if len(names) > 1 and "links" in group:
            for link in names:
                d = group["links"].get(link)
                if d is not None and "tip_deflection" in d and d["tip_deflection"].shape[0] == len(self.t):
                    self.tips.append((link, np.asarray(d["tip_deflection"][:])))
        elif "tip_deflection" in self.data:
            self.tips.append(("", self.data["tip_deflection"]))

    def _from_run(self, run, name):
        kept = list(run.names)
        if "time" not in kept:
            raise ValueError("run %s kept no series (run with keep_series=True)" % run.name)
        self.name = name or run.name
        self.status = str(run.status)
        model = run.model
        self.n = int(model.n) if model is not None else -1
        self.t = np.asarray(run.table("time"))[:, 0]
        self.data = {}
        for key in SERIES:
            if key in kept:
                table = np.asarray(run.table(key))
                if table.ndim == 2 and table.shape[0] == len(self.t):
                    self.data[key] = table
        ncols = self.data["joint_q"].shape[1] if "joint_q" in self.data else 0
        info = run.info("joint_q") if "joint_q" in kept else {}
        self.joints = list(info.get("columns", []))
        if len(self.joints) != ncols:
            self.joints = ["joint %d" % (j + 1) for j in range(ncols)]
        units = list(info.get("units", []))
        self.types = ["prismatic" if u == "m" else "revolute" for u in units]
        if len(self.types) != ncols:
            self.types = ["revolute"] * ncols
        links = [link["name"] for link in model.links] if model is not None else []
        self.tips = []
        if len(links) > 1:
            for link in links:
                key = "links/%s/tip_deflection" % link
                if key in kept:
                    table = np.asarray(run.table(key))
                    if table.shape[0] == len(self.t):
                        self.tips.append((link, table))
        elif "tip_deflection" in self.data:
            self.tips.append(("", self.data["tip_deflection"]))

    def col(self, key, j):
        return self.data[key][:, j]

    def title(self, what):
        head = "%s%s, %s" % (self.case + " " if self.case else "", self.name, "n = %d" % self.n if self.n >= 0 else "")
        suffix = "" if self.status == "completed" else "\n" + wrap("[status: %s]" % self.status)
        return "%s: %s%s" % (head, what, suffix)


def _open(path):
    """An HDF5 results file for reading; a run killed while it wrote (SWMR flags still set) opens
    as SWMR reader."""
    try:
        return h5py.File(path, "r")
    except OSError:
        return h5py.File(path, "r", libver="latest", swmr=True)


def read(path):
    """The runs of a results file, {group name: Run}, in the file's order."""
    with _open(os.fspath(path)) as f:
        case = os.path.splitext(os.path.basename(text_attr(f, "case_path")))[0]
        return {k: Run(f[k], k, case) for k in f if isinstance(f[k], h5py.Group) and "time" in f[k]}


def _run(run, name=None):
    """A Run of this module from what the public functions accept."""
    if isinstance(run, Run):
        return run
    if isinstance(run, (str, bytes, os.PathLike)):
        runs = read(run)
        if not runs:
            raise ValueError("%s: no run groups (with a `time` dataset)" % os.fsdecode(run))
        if name is None:
            return list(runs.values())[-1]
        if name not in runs:
            raise KeyError("%s: no run %r (have %s)" % (os.fsdecode(run), name, ", ".join(runs)))
        return runs[name]
    return Run(run, name)


def _runs(runs):
    """{name: Run} of the paper's rigid, kinematic and force runs (rfem.Runs, a dict or a path)."""
    if isinstance(runs, (str, bytes, os.PathLike)):
        return read(runs)
    if isinstance(runs, dict):
        return {k: _run(v) for k, v in runs.items()}
    out = {}
    for r in runs:
        r = _run(r)
        out[r.name.split("/")[-1]] = r
    return out


_FIGURE = None


def new_figure(figsize=None, dpi=None):
    """A matplotlib Figure outside pyplot's care (nothing piles up when a loop makes many; save it
    with fig.savefig) that Jupyter shows inline as a cell's value or by display(fig), with or
    without `%matplotlib inline`."""
    global _FIGURE
    if _FIGURE is None:
        import io

        from matplotlib.figure import Figure

        class InlineFigure(Figure):
            def _repr_png_(self):
                buf = io.BytesIO()
                self.savefig(buf, format="png", bbox_inches="tight")
                return buf.getvalue()

        _FIGURE = InlineFigure
    return _FIGURE(figsize=figsize, dpi=dpi)


def _new_figure(figsize):
    return new_figure(figsize)


def _axes(ax, figsize):
    """(ax, whether this module made its Figure)."""
    if ax is not None:
        return ax, False
    return _new_figure(figsize).add_subplot(), True


def _subplots(fig, rows, figsize, **kw):
    """(fig, axes column, whether this module made the Figure)."""
    own = fig is None
    if own:
        fig = _new_figure(figsize)
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False, **kw)[:, 0]
    return fig, axes, own


def _done(fig, own):
    if own:
        fig.tight_layout()
    return fig


def negligible(y, scale):
    """True for a series that is identically zero or round-off against `scale`."""
    peak = np.max(np.abs(y)) if len(y) else 0.0
    return peak == 0.0 or peak < 1e-12 * max(scale, 1e-300)


def mean_acceleration(t, v):
    """(v[k+1] − v[k−1]) / (t[k+1] − t[k−1]): the mean over two output intervals (README)."""
    if len(t) < 3:
        return t, v
    return t[1:-1], (v[2:] - v[:-2]) / (t[2:] - t[:-2])[:, None] if v.ndim == 2 else (v[2:] - v[:-2]) / (t[2:] - t[:-2])


def tip_sign(j, paper_signs=False):
    """The sign the tip deflection j (u1, u2, θ) is drawn with: u1, u2 with the paper's (Kane's)
    sign, the opposite of the physical one, with paper_signs."""
    return -1.0 if paper_signs and j < 2 else 1.0


def finish(ax, xlabel=None, ylabel=None, legend=True):
    if xlabel:
        ax.set_xlabel(xlabel)
    if ylabel:
        ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.4)
    if legend and ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize="small")


def _joint_rows(run):
    kinds = [k for k in ("revolute", "prismatic") if k in run.types]
    return [(key, k) for key in JOINT_KEYS if key in run.data for k in kinds]


def _draw_joint(ax, run, key, kind):
    unit = UNITS[kind][JOINT_KEYS.index(key)]
    sym = {"joint_q": "q", "joint_v": "v", "joint_tau": "τ"}[key]
    for j, name in enumerate(run.joints):
        if run.types[j] == kind:
            ax.plot(run.t, run.col(key, j), label=name)
    finish(ax, ylabel="%s [%s]" % (sym, unit))


def joint(run, key="joint_q", ax=None, kind=None, name=None):
    """One joint series ("joint_q", "joint_v" or "joint_tau") against t, a line per joint of one
    kind ("revolute" or "prismatic"; default: the first the run has), on `ax`. Returns the Figure."""
    run = _run(run, name)
    if key not in JOINT_KEYS:
        raise ValueError("key: one of %s (got %r)" % (", ".join(JOINT_KEYS), key))
    if key not in run.data:
        raise ValueError("run %s has no series %s" % (run.name, key))
    kind = kind or next((k for k in ("revolute", "prismatic") if k in run.types), "revolute")
    ax, own = _axes(ax, (8, 3.2))
    _draw_joint(ax, run, key, kind)
    ax.set_xlabel("t [s]")
    if own:
        ax.set_title(run.title("joint " + {"joint_q": "coordinates", "joint_v": "rates", "joint_tau": "torques"}[key]))
    return _done(ax.figure, own)


def joints(run, fig=None, name=None):
    """The joints' coordinates, rates and torques against t (G_joints.png); revolute and
    prismatic joints on separate axes (their units differ). Returns the Figure."""
    run = _run(run, name)
    rows = _joint_rows(run)
    if not rows:
        raise ValueError("run %s has no joint series" % run.name)
    fig, axes, own = _subplots(fig, len(rows), (8, 2.4 * len(rows) + 0.8))
    for ax, (key, kind) in zip(axes, rows):
        _draw_joint(ax, run, key, kind)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title(run.title("joint coordinates, rates and torques"))
    return _done(fig, own)


def _component(component):
    names = [n for n, _ in TIP_LABELS]
    if component in names:
        return names.index(component)
    if isinstance(component, (int, np.integer)) and 0 <= component < 3:
        return int(component)
    raise ValueError("component: u1, u2, theta or 0, 1, 2 (got %r)" % (component,))


def _draw_tip(ax, run, j, paper_signs, scale=None):
    name, ylabel = TIP_LABELS[j]
    if scale is None:
        scale = max(np.max(np.abs(td[:, :2])) if td.size else 0.0 for _, td in run.tips)
    for i, (link, td) in enumerate(run.tips):
        y = tip_sign(j, paper_signs) * td[:, j]
        label = "%s %s" % (name, link) if link else name
        color = "C%d" % (i if len(run.tips) > 1 else j)
        # θ is round-off below 1e-12 of a radian (or of the deflections' scale): it was compared with
        # 1e13 times its own peak, which called every torsion round-off.
        if negligible(y, scale if j < 2 else max(scale, 1.0)):
            ax.axhline(0.0, color=color, label=label)
            ax.text(0.5, 0.6 - 0.15 * i, "%s%s" % (link + ": " if link else "", "identically zero" if not np.any(y) else
                    "round-off only (|%s| ≤ %.1e)" % (name, np.max(np.abs(y)))),
                    transform=ax.transAxes, ha="center", color="0.35")
        else:
            ax.plot(run.t, y, label=label, color=color)
    finish(ax, ylabel=ylabel)


def tip(run, component="u1", ax=None, paper_signs=False, name=None):
    """One tip deflection (u1, u2 [m] or theta [rad]; or 0, 1, 2) of every flexible link against
    t on `ax`. Returns the Figure."""
    run = _run(run, name)
    j = _component(component)
    if not run.tips:
        raise ValueError("run %s has no tip deflections" % run.name)
    ax, own = _axes(ax, (8, 3.2))
    _draw_tip(ax, run, j, paper_signs)
    ax.set_xlabel("t [s]")
    if own:
        ax.set_title(run.title("tip deflection " + TIP_LABELS[j][0]))
    return _done(ax.figure, own)


def tips(run, fig=None, paper_signs=False, name=None):
    """The tip deflections u1, u2 and torsion θ (of every link: one colour per link) against t
    (G_tip.png). Returns the Figure."""
    run = _run(run, name)
    if not run.tips:
        raise ValueError("run %s has no tip deflections" % run.name)
    scale = max(np.max(np.abs(td[:, :2])) if td.size else 0.0 for _, td in run.tips)
    fig, axes, own = _subplots(fig, 3, (8, 7))
    for j, ax in enumerate(axes):
        _draw_tip(ax, run, j, paper_signs, scale)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title(run.title("tip deflections u1, u2 and torsion θ" + (" of every link" if len(run.tips) > 1 else "") +
                                (" (the paper's signs)" if paper_signs else "")))
    return _done(fig, own)


def energy(run, fig=None, name=None):
    """The energies against t and the drift of their balance (G_energy.png). Returns the Figure."""
    run = _run(run, name)
    if "energy" not in run.data:
        raise ValueError("run %s has no series energy" % run.name)
    e = run.data["energy"]
    fig, (ax1, ax2), own = _subplots(fig, 2, (8, 6.5), gridspec_kw={"height_ratios": [2, 1]})
    for j, label in enumerate(ENERGY_LABELS[:e.shape[1] - 1]):
        # Input work often equals kinetic energy: dash it so both stay visible.
        ax1.plot(run.t, e[:, j], label=label, linestyle=ENERGY_STYLES[j], linewidth=2.4 if j == 0 else 1.5)
    finish(ax1, ylabel="energy [J]")
    ax1.set_title(run.title("energy"))
    balance = e[:, -1]
    ax2.plot(run.t, balance - balance[0], color="k", label="balance − balance(0)")
    finish(ax2, "t [s]", "balance drift [J]")
    return _done(fig, own)


def momentum(run, fig=None, name=None):
    """Linear and angular momentum of all bodies against t (G_momentum.png; constant on a free
    base without gravity). Returns the Figure."""
    run = _run(run, name)
    if "momentum" not in run.data:
        raise ValueError("run %s has no series momentum" % run.name)
    p = run.data["momentum"]
    fig, (ax1, ax2), own = _subplots(fig, 2, (8, 6))
    for j, label in enumerate(["px", "py", "pz"]):
        ax1.plot(run.t, p[:, j], label=label)
    finish(ax1, ylabel="linear momentum [kg m/s]")
    ax1.set_title(run.title("momentum of all bodies (constant without gravity)"))
    for j, label in enumerate(["Lx", "Ly", "Lz"]):
        ax2.plot(run.t, p[:, 3 + j], label=label)
    finish(ax2, "t [s]", "angular momentum about {0} [kg m²/s]")
    return _done(fig, own)


def _run_figures(run, paper_signs, note):
    """(file name, Figure) of one run group: G_joints, G_tip, G_energy, G_momentum."""
    g = run.name
    if _joint_rows(run):
        yield "%s_joints.png" % g, joints(run)
    # A run with every link rigid has no tip deflections.
    if run.tips and run.n == 0:
        note("run %s has rigid links only: no tip deflections to draw" % g)
    if run.tips and run.n != 0:
        yield "%s_tip.png" % g, tips(run, paper_signs=paper_signs)
    if "energy" in run.data:
        yield "%s_energy.png" % g, energy(run)
    # Momentum of a free-floating base's system (joints base_x … base_roll come first).
    if "momentum" in run.data and run.joints[:1] == ["base_x"]:
        yield "%s_momentum.png" % g, momentum(run)


def compare(ax, runs_series, ylabel, xlabel=None):
    """Plot (t, y, label) series on one axis."""
    for k, (t, y, label) in enumerate(runs_series):
        ax.plot(t, y, label=label, linestyle="-" if k == 0 else "--")
    finish(ax, xlabel, ylabel)


def status_note(*runs):
    bad = ["%s: %s" % (r.name, r.status) for r in runs if r.status != "completed"]
    return "\n" + wrap("[%s]" % "; ".join(bad)) if bad else ""


PAPER_FIGURES = {5: "fig5_tip.png", 6: "fig6_torque3.png", 7: "fig7_velocity3.png", 8: "fig8_accel12.png"}


def paper_figure(runs, number, fig=None, ax=None, paper_signs=False):
    """The paper's Figure 5 (tip deflections, kinematic vs force input), 6 (joint-3 torque, rigid
    vs flexible link), 7 (joint-3 velocity) or 8 (joint 1 and 2 accelerations) from the runs of
    the paper's procedure (rfem.Runs, {name: run} or a results file's path). Figures 6 and 7 are
    one panel (`ax=`), 5 and 8 several (`fig=`). Returns the Figure."""
    runs = _runs(runs)
    missing = [g for g in ("rigid", "kinematic", "force") if g not in runs]
    if missing:
        raise ValueError("the paper's figures need the runs rigid, kinematic and force (missing: %s)"
                         % ", ".join(missing))
    rig, kin, frc = runs["rigid"], runs["kinematic"], runs["force"]
    head = "%sn = %d: " % (kin.case + ", " if kin.case else "", kin.n)
    if number == 5:  # tip deflections, kinematic vs force input
        fig, axes, own = _subplots(fig, 3, (8, 7.5))
        for j, (a, (_, ylabel)) in enumerate(zip(axes, TIP_LABELS)):
            compare(a, [(kin.t, tip_sign(j, paper_signs) * kin.col("tip_deflection", j), "kinematic input"),
                        (frc.t, tip_sign(j, paper_signs) * frc.col("tip_deflection", j), "force input")], ylabel)
        axes[-1].set_xlabel("t [s]")
        axes[0].set_title(head + "Fig. 5: tip deflections u1, u2 and torsion θ of link 3" +
                          (" (the paper's signs)" if paper_signs else "") + status_note(kin, frc))
        return _done(fig, own)
    if number == 6:  # joint-3 torque, rigid vs flexible link
        ax, own = _axes(ax, (8, 4.5))
        compare(ax, [(rig.t, rig.col("joint_tau", 2), "rigid link 3"),
                     (kin.t, kin.col("joint_tau", 2), "flexible link 3 (kinematic input)")], "τ3 [N m]", "t [s]")
        ax.set_title(head + "Fig. 6: joint-3 torque, rigid vs flexible link" + status_note(rig, kin))
        return _done(ax.figure, own)
    if number == 7:  # joint-3 velocity, kinematic vs force input
        ax, own = _axes(ax, (8, 4.5))
        compare(ax, [(kin.t, kin.col("joint_v", 2), "kinematic input"),
                     (frc.t, frc.col("joint_v", 2), "force input")], "dψ3/dt [rad/s]", "t [s]")
        ax.set_title(head + "Fig. 7: joint-3 velocity" + status_note(kin, frc))
        return _done(ax.figure, own)
    if number == 8:
        # Joint 1 and 2 accelerations, kinematic vs force input, as means over two output intervals:
        # the instantaneous acceleration of a free joint carries an unresolved stiff mode.
        fig, axes, own = _subplots(fig, 2, (8, 6.5))
        tk, ak = mean_acceleration(kin.t, kin.data["joint_v"])
        tf, af = mean_acceleration(frc.t, frc.data["joint_v"])
        for j, a in enumerate(axes):
            compare(a, [(tk, ak[:, j], "kinematic input"), (tf, af[:, j], "force input")],
                    "d²ψ%d/dt² [rad/s²]" % (j + 1))
            a.set_title("joint %d (mean over two output intervals)" % (j + 1), fontsize="medium")
        axes[-1].set_xlabel("t [s]")
        fig.suptitle(head + "Fig. 8: joint 1 and 2 accelerations" + status_note(kin, frc))
        return _done(fig, own)
    raise ValueError("number: the paper's Figure 5, 6, 7 or 8 (got %r)" % (number,))


def quantity_unit(q, joint_units=()):
    """The unit of a refine quantity (README, "Quantities"); joint_units: "rad" or "m" per joint."""
    name = q.split("/")[-1]
    if name.startswith(("mode:", "axial:", "bending-", "torsion:")):
        return "Hz"
    if name.startswith("tip:"):
        return "m" if name[4:5] == "u" else "rad"
    body = name.split(":")[-1].split("@")[0].split("[")[0].split("-")[0]
    if body in ("u1", "u2"):
        return "m"
    if body == "theta":
        return "rad"
    for prefix, units in (("tau", ("N m", "N")), ("q", ("rad", "m")), ("v", ("rad/s", "m/s")), ("a", ("rad/s²", "m/s²"))):
        if body.startswith(prefix) and body[len(prefix):].isdigit():
            j = int(body[len(prefix):]) - 1
            if 0 <= j < len(joint_units):
                return units[0] if joint_units[j] == "rad" else units[1]
            return " or ".join(units)
    return ""


def _refine_tables(source):
    """[(sub, quantity, n, value, fitted order, reference or None, warnings, over)] and the status
    of a refinement: an h5py `refine` group or an rfem.RefineResult. over: "n", or "modes" for a
    series over modes (n then the modes m, 0 the full model)."""
    if isinstance(source, h5py.Group):
        over = "n" if "n" in source else "modes"
        n_all = np.asarray(source[over][:], dtype=float).ravel()
        subs = sorted((k for k in source if k.startswith("q") and isinstance(source[k], h5py.Group)),
                      key=lambda k: int(k[1:])) or [None]
        tables = []
        for sub in subs:
            g = source[sub] if sub else source
            v = np.asarray(g["value"][:], dtype=float).ravel()
            ref = float(np.asarray(g.attrs["reference"]).ravel()[0]) if "reference" in g.attrs else None
            tables.append((sub, text_attr(g, "quantity", "value"), n_all[:len(v)], v,
                           float(np.asarray(g.attrs.get("fitted_order", np.nan)).ravel()[0]), ref,
                           text_attr(g, "warnings", ""), over))
        return tables, text_attr(source, "status", "completed")
    tables = []
    for k, t in enumerate(source["tables"]):
        v = np.asarray(t["value"], dtype=float).ravel()
        ref = t.get("reference")
        ref = float(ref) if ref is not None and np.isfinite(ref) else None
        fitted = t.get("fitted_order")
        over = "n" if "n" in t else "modes"
        tables.append(("q%d" % k, t["quantity"], np.asarray(t[over], dtype=float).ravel()[:len(v)], v,
                       float(fitted) if fitted is not None else np.nan, ref, "\n".join(t.get("warnings", [])), over))
    return tables, str(source.get("status", "completed"))


def _draw_refinement(ax, quantity, n, v, fitted, ref, warnings, over, status, case_name, joint_units):
    import matplotlib.ticker
    unit = quantity_unit(quantity, joint_units)
    if over == "modes":  # reduced links: each m's distance from the full model (the row m = 0)
        full = v[n == 0][0] if np.any(n == 0) else np.nan
        x, err = n[n > 0], np.abs(v[n > 0] - full)
        keep = (err > 0) & np.isfinite(err)
        if np.any(keep):
            ax.loglog(x[keep], err[keep], "o-", label="|value − full model's|")
        finish(ax, "modes kept per flexible link (m)", "|%s − full model's| [%s]" % (quantity, unit))
        if len(x):
            ax.set_xticks(x)
            ax.set_xticklabels(["%g" % t for t in x])
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_title("Reduced links%s: %s\nfull model %.10g %s%s" % (" of " + case_name if case_name else "", quantity, full, unit,
                                                                   "" if status == "completed" else " (%s)" % status), fontsize="medium")
        return
    if ref is not None:
        x, err = n, np.abs(v - ref)
        label, ylabel = "|value − Richardson value|", "|%s − reference| [%s]" % (quantity, unit)
        note = "Richardson value %.10g %s" % (ref, unit)
    else:
        x, err = n[1:], np.abs(np.diff(v))
        label, ylabel = "|change from the previous n|", "|Δ %s| [%s]" % (quantity, unit)
        note = "no trusted Richardson value: successive changes"
    keep = (err > 0) & (x > 0) & np.isfinite(err)
    x, err = x[keep], err[keep]
    if len(x):
        ax.loglog(x, err, "o-", label=label)
    changes = np.abs(np.diff(v))
    if np.isfinite(fitted) and len(changes) and np.all(changes > 0):
        xs = n[1:]
        c = np.exp(np.mean(np.log(changes) + fitted * np.log(xs)))
        ax.loglog(xs, c * xs ** (-fitted), "k--", label="order %.2f (least squares, all changes)" % fitted)
    finish(ax, "n (number of rfes)", ylabel)
    ax.grid(True, which="minor", alpha=0.15)
    if len(x):
        ax.set_xticks(x)
        ax.set_xticklabels(["%g" % t for t in x])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    title = "Refinement study%s: %s\n%s" % (" of " + case_name if case_name else "", quantity, note)
    if status != "completed":
        title += " (%s)" % status
    ax.set_title(title, fontsize="medium")
    if warnings:
        ax.text(0.02, 0.02, wrap("warning: " + warnings.replace("\n", "; ")), transform=ax.transAxes,
                fontsize="small", color="darkred", va="bottom")


def refinement(result, quantity=None, ax=None, case_name="", joint_units=()):
    """A refinement study's convergence (refine_convergence.png): |value − Richardson value| when
    the series is trusted, else the successive changes, against n on log–log axes, with a line of
    the order fitted by least squares over all changes. result: an rfem.RefineResult (rfem.refine),
    an h5py `refine` group or a results file's path; quantity: its name or index (default: the
    first). Returns the Figure."""
    if isinstance(result, (str, bytes, os.PathLike)):
        with _open(os.fspath(result)) as f:
            if "refine" not in f:
                raise ValueError("%s: no `refine` group" % os.fsdecode(result))
            return refinement(f["refine"], quantity, ax, case_name, joint_units)
    tables, status = _refine_tables(result)
    if quantity is None:
        table = tables[0]
    elif isinstance(quantity, (int, np.integer)):
        table = tables[quantity]
    else:
        found = [t for t in tables if t[1] == quantity]
        if not found:
            raise KeyError("no quantity %r (have %s)" % (quantity, ", ".join(t[1] for t in tables)))
        table = found[0]
    ax, own = _axes(ax, (7, 5))
    _draw_refinement(ax, *table[1:], status, case_name, joint_units)
    return _done(ax.figure, own)


def _refine_figures(group, case_name, joint_units):
    tables, status = _refine_tables(group)
    for sub, *table in tables:
        ax, _ = _axes(None, (7, 5))
        _draw_refinement(ax, *table, status, case_name, joint_units)
        ax.figure.tight_layout()
        yield ("refine_convergence.png" if sub in (None, "q0") else "refine_convergence_%s.png" % sub), ax.figure


def _sweep_figures(f):
    """A sweep's index: each quantity against each numeric parameter, one line per combination of
    the others; over n, also the changes between successive n on log scales with their observed
    orders (the slope: 2 for rfem's converged series)."""
    import matplotlib
    import matplotlib.cm
    import matplotlib.colors
    import matplotlib.ticker
    names, quantities = list_attr(f["parameters"], "columns"), list_attr(f["quantities"], "columns")
    values, table = f["parameters"][()], f["quantities"][()]
    stem = os.path.splitext(os.path.basename(text_attr(f, "sweep_path")))[0] or "sweep"
    for j, p in enumerate(names):
        x = values[:, j]
        if not np.all(np.isfinite(x)) or len(np.unique(x)) < 2:
            continue
        others = [i for i in range(len(names)) if i != j]
        keys = sorted({tuple(values[r, others]) for r in range(len(x))}, key=lambda k: tuple(np.nan_to_num(k)))
        for qi, q in enumerate(quantities):
            by_n = p == "n"
            fig = _new_figure((11 if by_n else 7, 4.5))
            axes = fig.subplots(1, 2 if by_n else 1, squeeze=False)
            ax = axes[0][0]
            many = len(keys) > 6  # then colours along a colour bar of the first other parameter, orders at the ends
            cmap = matplotlib.colormaps["viridis"]
            for ki, key in enumerate(keys):
                rows = [r for r in range(len(x)) if tuple(values[r, others]) == key]
                rows.sort(key=lambda r: x[r])
                xs, ys = x[rows], table[rows, qi]
                label = ", ".join("%s = %g" % (names[i], v) for i, v in zip(others, key)) or None
                style = dict(color=cmap(ki / max(1, len(keys) - 1)), lw=1, ms=3) if many else dict(label=label)
                ax.plot(xs, ys, "o-", **style)
                if by_n and len(xs) >= 2:
                    d = np.abs(np.diff(ys))
                    ok = d > 0
                    axes[0][1].loglog(xs[1:][ok], d[ok], "o-", **style)
                    for a in range(1, len(d)):
                        if many and ki not in (0, len(keys) - 1):
                            continue
                        if d[a - 1] > 0 and d[a] > 0:
                            order = np.log(d[a - 1] / d[a]) / np.log(xs[a + 1] / xs[a])
                            axes[0][1].annotate("%.2f" % order, (xs[a + 1], d[a]), fontsize="small",
                                                textcoords="offset points", xytext=(4, 4))
            if many and others:
                finite = [k[0] for k in keys if np.isfinite(k[0])]
                if finite:
                    norm = matplotlib.colors.Normalize(min(finite), max(finite))
                    sm = matplotlib.cm.ScalarMappable(cmap=cmap, norm=norm)
                    fig.colorbar(sm, ax=axes[0][-1], label=names[others[0]])
            if by_n:
                ax.set_xscale("log")
                axes[0][1].xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
                finish(axes[0][1], "n (rfes)", "|change of %s| from the previous n" % q)
                axes[0][1].set_title("observed orders (slopes)", fontsize="medium")
            finish(ax, p, q)
            fig.suptitle("%s: %s against %s" % (stem, q, p), fontsize="medium")
            fig.tight_layout()
            safe = re.sub(r"[^A-Za-z0-9_.-]+", "_", "%s_vs_%s" % (q, p))
            yield "sweep_%s.png" % safe, fig


def write(results, outdir=None, format="png", paper_signs=False, echo=None, note=None):
    """Every figure `rfem plot` draws for a results, refinement or sweep file, written into outdir
    (default: the file's directory) as png, pdf or svg; returns the paths written. echo(path) is
    called after each figure, note(text) with what is not drawn and why. A file it cannot read or
    a directory it cannot write raises PlotError (a RuntimeError) with the one-line message."""
    if format not in FORMATS:
        raise ValueError("format: png, pdf or svg (got %r)" % (format,))
    path = os.fspath(results)
    outdir = os.fspath(outdir) if outdir else os.path.dirname(os.path.abspath(path))
    note = note or (lambda text: None)
    written = []

    def save(figures):
        for name, fig in figures:
            out = os.path.join(outdir, os.path.splitext(name)[0] + "." + format)
            fig.savefig(out, dpi=DPI)
            written.append(out)
            if echo:
                echo(out)

    try:
        if not os.path.isfile(path):
            raise OSError("not a file" if os.path.exists(path) else "no such file")
        if not os.access(path, os.R_OK):
            raise OSError("permission denied")
        if not h5py.is_hdf5(path):
            raise OSError("not an HDF5 file")
        with _open(path) as f:
            groups = [k for k in f if isinstance(f[k], h5py.Group)]
            case = os.path.splitext(os.path.basename(text_attr(f, "case_path")))[0]
            runs = {k: Run(f[k], k, case) for k in groups if "time" in f[k]}
            has_refine = "refine" in groups and ("n" in f["refine"] or "modes" in f["refine"]) and "value" in f["refine"]
            if text_attr(f, "procedure") == "sweep" and "quantities" in f:
                os.makedirs(outdir, exist_ok=True)
                save(_sweep_figures(f))
                return written
            if not runs and not has_refine:
                raise ValueError("no run groups (with a `time` dataset) and no `refine` group")
            empty = [k for k, r in runs.items() if len(r.t) == 0]
            if empty and not has_refine and len(empty) == len(runs):
                raise ValueError("the run%s %s ha%s no output steps" % ("s" if len(empty) > 1 else "", ", ".join(empty),
                                                                       "ve" if len(empty) > 1 else "s"))
            for k in empty:
                note("run %s has no output steps (status: %s)" % (k, runs[k].status))
                del runs[k]
            try:
                os.makedirs(outdir, exist_ok=True)
                if not os.access(outdir, os.W_OK):
                    raise OSError("not writable")
            except OSError as exc:
                raise PlotError("%s: cannot write the figures there (%s)" % (outdir, exc.strerror or exc)) from None
            if text_attr(f, "procedure") == "paper" and all(g in runs for g in ("rigid", "kinematic", "force")):
                save((PAPER_FIGURES[k], paper_figure(runs, k, paper_signs=paper_signs)) for k in (5, 6, 7, 8))
            for run in runs.values():
                save(_run_figures(run, paper_signs, note))
            if has_refine:
                case = text_attr(f, "case_path")
                units = []  # the joints' units, from any run of the study (n12/run, …)
                f.visititems(lambda name, obj: units.extend(list_attr(obj, "joint_units"))
                             if not units and isinstance(obj, h5py.Group) and "joint_units" in obj.attrs else None)
                save(_refine_figures(f["refine"], os.path.splitext(os.path.basename(case))[0] if case else "", units))
    except PlotError:
        raise
    except (OSError, KeyError, ValueError, IndexError, TypeError, RuntimeError) as exc:  # (h5py: damaged files)
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise PlotError("%s: %s" % (path, reason)) from exc
    return written


def main(argv=None):
    """`rfem plot` (python3 -m rfem.plots RESULT.h5 …): the figures, a line "wrote PATH" each; a
    file it cannot draw: one line "rfem plot: error: …" on stderr, exit code 2."""
    parser = argparse.ArgumentParser(prog="rfem plot", description=__doc__.splitlines()[0])
    parser.add_argument("result", metavar="RESULT.h5", help="HDF5 file written by rfem")
    parser.add_argument("-o", "--outdir", help="output directory (default: that of RESULT.h5)")
    parser.add_argument("--format", choices=FORMATS, default="png",
                        help="file format of the figures (pdf and svg scale for print)")
    parser.add_argument("--paper-signs", action="store_true",
                        help="draw u1, u2 with the paper's (Kane's) sign, the opposite of the physical displacement")
    args = parser.parse_args(argv)
    try:
        write(args.result, args.outdir, args.format, args.paper_signs, echo=lambda path: print("wrote %s" % path),
              note=lambda text: print("rfem plot: note: %s" % text, file=sys.stderr))
    except PlotError as exc:
        print("rfem plot: error: %s" % exc, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
