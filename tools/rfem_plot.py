#!/usr/bin/python3
"""Plot the results of `rfem run` (or a refinement study) from its HDF5 file.

    /usr/bin/python3 tools/rfem_plot.py RESULT.h5 [-o OUTDIR]

    /usr/bin/python3 tools/rfem_plot.py RESULT.h5 [-o OUTDIR] [--format png|pdf|svg] [--paper-signs]

Writes figures (PNG by default) into OUTDIR (default: the directory of RESULT.h5):
  * for every run group G: G_joints.png, G_tip.png, G_energy.png, and G_momentum.png on a free
    base (linear and angular momentum: constant without gravity);
  * for procedure "paper": fig5_tip.png, fig6_torque3.png, fig7_velocity3.png, fig8_accel12.png
    (the layout of the paper's Figures 5-8);
  * for a file with a `refine` group: refine_convergence.png (and refine_convergence_qK.png for
    every further quantity K).
Needs Debian's python3-matplotlib, python3-h5py and python3-numpy (run with /usr/bin/python3).
"""
import argparse
import os
import re
import sys
import textwrap

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

DPI = 120
SERIES = ["joint_q", "joint_v", "joint_a", "joint_tau", "tip_deflection", "energy", "momentum"]
TIP_LABELS = [("u1", "u1 [m]"), ("u2", "u2 [m]"), ("theta", "θ [rad]")]
ENERGY_LABELS = ["kinetic", "elastic", "gravity", "input work", "dissipated"]
ENERGY_STYLES = ["-", "-", "-", "--", ":"]


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
    """The series of one run group, read into memory."""

    def __init__(self, group, name, case=""):
        self.name = name
        self.case = case
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
            for name in names:
                d = group["links"].get(name)
                if d is not None and "tip_deflection" in d and d["tip_deflection"].shape[0] == len(self.t):
                    self.tips.append((name, np.asarray(d["tip_deflection"][:])))
        elif "tip_deflection" in self.data:
            self.tips.append(("", self.data["tip_deflection"]))

    def col(self, key, j):
        return self.data[key][:, j]

    def title(self, what):
        head = "%s%s, %s" % (self.case + " " if self.case else "", self.name, "n = %d" % self.n if self.n >= 0 else "")
        suffix = "" if self.status == "completed" else "\n" + wrap("[status: %s]" % self.status)
        return "%s: %s%s" % (head, what, suffix)


def negligible(y, scale):
    """True for a series that is identically zero or round-off against `scale`."""
    peak = np.max(np.abs(y)) if len(y) else 0.0
    return peak == 0.0 or peak < 1e-12 * max(scale, 1e-300)


def mean_acceleration(t, v):
    """(v[k+1] − v[k−1]) / (t[k+1] − t[k−1]): the mean over two output intervals (README)."""
    if len(t) < 3:
        return t, v
    return t[1:-1], (v[2:] - v[:-2]) / (t[2:] - t[:-2])[:, None] if v.ndim == 2 else (v[2:] - v[:-2]) / (t[2:] - t[:-2])


FORMAT = "png"       # --format: png, pdf or svg
PAPER_SIGNS = False  # --paper-signs: u1, u2 with the sign of the paper (Kane's), not the physical one


def tip_sign(j):
    """The sign the tip deflection j (u1, u2, θ) is drawn with."""
    return -1.0 if PAPER_SIGNS and j < 2 else 1.0


def save(fig, outdir, name):
    path = os.path.join(outdir, os.path.splitext(name)[0] + "." + FORMAT)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    print("wrote %s" % path)


def finish(ax, xlabel=None, ylabel=None, legend=True):
    if xlabel:
        ax.set_xlabel(xlabel)
    if ylabel:
        ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.4)
    if legend and ax.get_legend_handles_labels()[0]:
        ax.legend(loc="best", fontsize="small")


UNITS = {"revolute": ("rad", "rad/s", "N m"), "prismatic": ("m", "m/s", "N")}


def plot_run(run, outdir):
    """G_joints.png, G_tip.png, G_energy.png for one run group."""
    g = run.name
    # Joints: q, v, tau — revolute and prismatic joints on separate axes (their units differ).
    kinds = [k for k in ("revolute", "prismatic") if k in run.types]
    rows = [(key, k) for key in ("joint_q", "joint_v", "joint_tau") if key in run.data for k in kinds]
    if rows:
        fig, axes = plt.subplots(len(rows), 1, sharex=True, figsize=(8, 2.4 * len(rows) + 0.8), squeeze=False)
        for ax, (key, kind) in zip(axes[:, 0], rows):
            unit = UNITS[kind][("joint_q", "joint_v", "joint_tau").index(key)]
            sym = {"joint_q": "q", "joint_v": "v", "joint_tau": "τ"}[key]
            for j, name in enumerate(run.joints):
                if run.types[j] == kind:
                    ax.plot(run.t, run.col(key, j), label=name)
            finish(ax, ylabel="%s [%s]" % (sym, unit))
        axes[-1, 0].set_xlabel("t [s]")
        axes[0, 0].set_title(run.title("joint coordinates, rates and torques"))
        fig.tight_layout()
        save(fig, outdir, "%s_joints.png" % g)
    # Tip deflections (of every link: one colour per link); a run with every link rigid has none.
    if run.tips and run.n == 0:
        print("rfem plot: note: run %s has rigid links only: no tip deflections to draw" % g, file=sys.stderr)
    if run.tips and run.n != 0:
        scale = max(np.max(np.abs(td[:, :2])) if td.size else 0.0 for _, td in run.tips)
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7))
        for j, (ax, (name, ylabel)) in enumerate(zip(axes, TIP_LABELS)):
            for i, (link, td) in enumerate(run.tips):
                y = tip_sign(j) * td[:, j]
                label = "%s %s" % (name, link) if link else name
                color = "C%d" % (i if len(run.tips) > 1 else j)
                if negligible(y, scale if j < 2 else max(scale, np.max(np.abs(y)) * 1e13)):
                    ax.axhline(0.0, color=color, label=label)
                    ax.text(0.5, 0.6 - 0.15 * i, "%s%s" % (link + ": " if link else "", "identically zero" if not np.any(y) else
                            "round-off only (|%s| ≤ %.1e)" % (name, np.max(np.abs(y)))),
                            transform=ax.transAxes, ha="center", color="0.35")
                else:
                    ax.plot(run.t, y, label=label, color=color)
            finish(ax, ylabel=ylabel)
        axes[-1].set_xlabel("t [s]")
        axes[0].set_title(run.title("tip deflections u1, u2 and torsion θ" + (" of every link" if len(run.tips) > 1 else "") +
                                    (" (the paper's signs)" if PAPER_SIGNS else "")))
        fig.tight_layout()
        save(fig, outdir, "%s_tip.png" % g)
    # Energy and the drift of the balance.
    if "energy" in run.data:
        e = run.data["energy"]
        fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5),
                                       gridspec_kw={"height_ratios": [2, 1]})
        for j, name in enumerate(ENERGY_LABELS[:e.shape[1] - 1]):
            # Input work often equals kinetic energy: dash it so both stay visible.
            ax1.plot(run.t, e[:, j], label=name, linestyle=ENERGY_STYLES[j],
                     linewidth=2.4 if j == 0 else 1.5)
        finish(ax1, ylabel="energy [J]")
        ax1.set_title(run.title("energy"))
        balance = e[:, -1]
        ax2.plot(run.t, balance - balance[0], color="k", label="balance − balance(0)")
        finish(ax2, "t [s]", "balance drift [J]")
        fig.tight_layout()
        save(fig, outdir, "%s_energy.png" % g)
    # Momentum of a free-floating base's system (joints base_x … base_roll come first).
    if "momentum" in run.data and run.joints[:1] == ["base_x"]:
        p = run.data["momentum"]
        fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
        for j, name in enumerate(["px", "py", "pz"]):
            ax1.plot(run.t, p[:, j], label=name)
        finish(ax1, ylabel="linear momentum [kg m/s]")
        ax1.set_title(run.title("momentum of all bodies (constant without gravity)"))
        for j, name in enumerate(["Lx", "Ly", "Lz"]):
            ax2.plot(run.t, p[:, 3 + j], label=name)
        finish(ax2, "t [s]", "angular momentum about {0} [kg m²/s]")
        fig.tight_layout()
        save(fig, outdir, "%s_momentum.png" % g)


def compare(ax, runs_series, ylabel, xlabel=None):
    """Plot (t, y, label) series on one axis."""
    for k, (t, y, label) in enumerate(runs_series):
        ax.plot(t, y, label=label, linestyle="-" if k == 0 else "--")
    finish(ax, xlabel, ylabel)


def status_note(*runs):
    bad = ["%s: %s" % (r.name, r.status) for r in runs if r.status != "completed"]
    return "\n" + wrap("[%s]" % "; ".join(bad)) if bad else ""


def plot_paper(runs, outdir):
    """The paper's Figures 5-8 from the rigid, kinematic and force groups."""
    rig, kin, frc = runs["rigid"], runs["kinematic"], runs["force"]
    head = "%sn = %d: " % (kin.case + ", " if kin.case else "", kin.n)
    # Fig. 5: tip deflections, kinematic vs force input.
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7.5))
    for j, (ax, (_, ylabel)) in enumerate(zip(axes, TIP_LABELS)):
        compare(ax, [(kin.t, tip_sign(j) * kin.col("tip_deflection", j), "kinematic input"),
                     (frc.t, tip_sign(j) * frc.col("tip_deflection", j), "force input")], ylabel)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title(head + "Fig. 5: tip deflections u1, u2 and torsion θ of link 3" +
                      (" (the paper's signs)" if PAPER_SIGNS else "") + status_note(kin, frc))
    fig.tight_layout()
    save(fig, outdir, "fig5_tip.png")
    # Fig. 6: joint-3 torque, rigid vs flexible link.
    fig, ax = plt.subplots(figsize=(8, 4.5))
    compare(ax, [(rig.t, rig.col("joint_tau", 2), "rigid link 3"),
                 (kin.t, kin.col("joint_tau", 2), "flexible link 3 (kinematic input)")], "τ3 [N m]", "t [s]")
    ax.set_title(head + "Fig. 6: joint-3 torque, rigid vs flexible link" + status_note(rig, kin))
    fig.tight_layout()
    save(fig, outdir, "fig6_torque3.png")
    # Fig. 7: joint-3 velocity, kinematic vs force input.
    fig, ax = plt.subplots(figsize=(8, 4.5))
    compare(ax, [(kin.t, kin.col("joint_v", 2), "kinematic input"),
                 (frc.t, frc.col("joint_v", 2), "force input")], "dψ3/dt [rad/s]", "t [s]")
    ax.set_title(head + "Fig. 7: joint-3 velocity" + status_note(kin, frc))
    fig.tight_layout()
    save(fig, outdir, "fig7_velocity3.png")
    # Fig. 8: joint 1 and 2 accelerations, kinematic vs force input, as means over two output
    # intervals: the instantaneous acceleration of a free joint carries an unresolved stiff mode.
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    tk, ak = mean_acceleration(kin.t, kin.data["joint_v"])
    tf, af = mean_acceleration(frc.t, frc.data["joint_v"])
    for j, ax in enumerate(axes):
        compare(ax, [(tk, ak[:, j], "kinematic input"), (tf, af[:, j], "force input")],
                "d²ψ%d/dt² [rad/s²]" % (j + 1))
        ax.set_title("joint %d (mean over two output intervals)" % (j + 1), fontsize="medium")
    axes[-1].set_xlabel("t [s]")
    fig.suptitle(head + "Fig. 8: joint 1 and 2 accelerations" + status_note(kin, frc))
    fig.tight_layout()
    save(fig, outdir, "fig8_accel12.png")


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


def plot_refine(group, outdir, case_name="", joint_units=()):
    """Per quantity: |value − Richardson value| (when the series is trusted) or the successive
    changes, against n on log–log axes, with a line of the order fitted by least squares over all
    changes (independent of the extrapolation)."""
    n_all = np.asarray(group["n"][:], dtype=float).ravel()
    subs = sorted((k for k in group if k.startswith("q") and isinstance(group[k], h5py.Group)),
                  key=lambda k: int(k[1:])) or [None]
    status = text_attr(group, "status", "completed")
    for sub in subs:
        g = group[sub] if sub else group
        v = np.asarray(g["value"][:], dtype=float).ravel()
        n = n_all[:len(v)]
        quantity = text_attr(g, "quantity", "value")
        unit = quantity_unit(quantity, joint_units)
        warnings = text_attr(g, "warnings", "")
        fitted = float(np.asarray(g.attrs.get("fitted_order", np.nan)).ravel()[0])
        if "reference" in g.attrs:
            ref = float(np.asarray(g.attrs["reference"]).ravel()[0])
            x, err = n, np.abs(v - ref)
            label, ylabel = "|value − Richardson value|", "|%s − reference| [%s]" % (quantity, unit)
            note = "Richardson value %.10g %s" % (ref, unit)
        else:
            x, err = n[1:], np.abs(np.diff(v))
            label, ylabel = "|change from the previous n|", "|Δ %s| [%s]" % (quantity, unit)
            note = "no trusted Richardson value: successive changes"
        keep = (err > 0) & (x > 0) & np.isfinite(err)
        x, err = x[keep], err[keep]
        fig, ax = plt.subplots(figsize=(7, 5))
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
        fig.tight_layout()
        save(fig, outdir, "refine_convergence.png" if sub in (None, "q0") else "refine_convergence_%s.png" % sub)


def plot_sweep(f, outdir):
    """A sweep's index: each quantity against each numeric parameter, one line per combination of
    the others; over n, also the changes between successive n on log scales with their observed
    orders (the slope: 2 for rfem's converged series)."""
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
            fig, axes = plt.subplots(1, 2 if by_n else 1, figsize=(11 if by_n else 7, 4.5), squeeze=False)
            ax = axes[0][0]
            many = len(keys) > 6  # then colours along a colour bar of the first other parameter, orders at the ends
            cmap = plt.get_cmap("viridis")
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
                    sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(min(finite), max(finite)))
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
            save(fig, outdir, "sweep_%s.png" % safe)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="rfem_plot.py", description=__doc__.splitlines()[0])
    parser.add_argument("result", metavar="RESULT.h5", help="HDF5 file written by rfem")
    parser.add_argument("-o", "--outdir", help="output directory (default: that of RESULT.h5)")
    parser.add_argument("--format", choices=("png", "pdf", "svg"), default="png",
                        help="file format of the figures (pdf and svg scale for print)")
    parser.add_argument("--paper-signs", action="store_true",
                        help="draw u1, u2 with the paper's (Kane's) sign, the opposite of the physical displacement")
    args = parser.parse_args(argv)
    global FORMAT, PAPER_SIGNS
    FORMAT, PAPER_SIGNS = args.format, args.paper_signs
    outdir = args.outdir or os.path.dirname(os.path.abspath(args.result))
    try:
        if not os.path.isfile(args.result):
            raise OSError("not a file" if os.path.exists(args.result) else "no such file")
        if not os.access(args.result, os.R_OK):
            raise OSError("permission denied")
        if not h5py.is_hdf5(args.result):
            raise OSError("not an HDF5 file")
        try:
            f = h5py.File(args.result, "r")
        except OSError:  # a run killed while it wrote (SWMR flags still set): open it as SWMR reader
            f = h5py.File(args.result, "r", libver="latest", swmr=True)
        with f:
            groups = [k for k in f if isinstance(f[k], h5py.Group)]
            case = os.path.splitext(os.path.basename(text_attr(f, "case_path")))[0]
            runs = {k: Run(f[k], k, case) for k in groups if "time" in f[k]}
            has_refine = "refine" in groups and "n" in f["refine"] and "value" in f["refine"]
            if text_attr(f, "procedure") == "sweep" and "quantities" in f:
                os.makedirs(outdir, exist_ok=True)
                plot_sweep(f, outdir)
                return 0
            if not runs and not has_refine:
                raise ValueError("no run groups (with a `time` dataset) and no `refine` group")
            empty = [k for k, r in runs.items() if len(r.t) == 0]
            if empty and not has_refine and len(empty) == len(runs):
                raise ValueError("the run%s %s ha%s no output steps" % ("s" if len(empty) > 1 else "", ", ".join(empty),
                                                                       "ve" if len(empty) > 1 else "s"))
            for k in empty:
                print("rfem plot: note: run %s has no output steps (status: %s)" % (k, runs[k].status), file=sys.stderr)
                del runs[k]
            try:
                os.makedirs(outdir, exist_ok=True)
                if not os.access(outdir, os.W_OK):
                    raise OSError("not writable")
            except OSError as exc:
                print("rfem plot: error: %s: cannot write the figures there (%s)" % (outdir, exc.strerror or exc),
                      file=sys.stderr)
                return 2
            if text_attr(f, "procedure") == "paper" and all(
                    g in runs for g in ("rigid", "kinematic", "force")):
                plot_paper(runs, outdir)
            for run in runs.values():
                plot_run(run, outdir)
            if has_refine:
                case = text_attr(f, "case_path")
                units = []  # the joints' units, from any run of the study (n12/run, …)
                f.visititems(lambda name, obj: units.extend(list_attr(obj, "joint_units"))
                             if not units and isinstance(obj, h5py.Group) and "joint_units" in obj.attrs else None)
                plot_refine(f["refine"], outdir, os.path.splitext(os.path.basename(case))[0] if case else "", units)
    except (OSError, KeyError, ValueError, IndexError, TypeError, RuntimeError) as exc:  # (h5py: damaged files)
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        print("rfem plot: error: %s: %s" % (args.result, reason), file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
