#!/usr/bin/python3
"""Plot the results of `rfem run` (or a refinement study) from its HDF5 file.

    /usr/bin/python3 tools/rfem_plot.py RESULT.h5 [-o OUTDIR]

Writes PNGs into OUTDIR (default: the directory of RESULT.h5):
  * for every run group G: G_joints.png, G_tip.png, G_energy.png;
  * for procedure "paper": fig5_tip.png, fig6_torque3.png, fig7_velocity3.png, fig8_accel12.png
    (the layout of the paper's Figures 5-8);
  * for a file with a `refine` group: refine_convergence.png.
Needs Debian's python3-matplotlib, python3-h5py and python3-numpy (run with /usr/bin/python3).
"""
import argparse
import os
import sys
import textwrap

import matplotlib
import matplotlib.ticker

matplotlib.use("Agg")
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

DPI = 120
SERIES = ["joint_q", "joint_v", "joint_a", "joint_tau", "tip_deflection", "energy"]
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


class Run:
    """The series of one run group, read into memory."""

    def __init__(self, group, name):
        self.name = name
        self.status = text_attr(group, "status", "unknown")
        joints = text_attr(group, "joints")
        self.t = group["time"][:, 0]
        self.data = {key: np.asarray(group[key][:]) for key in SERIES
                     if key in group and group[key].ndim == 2
                     and group[key].shape[0] == len(self.t)}
        ncols = self.data["joint_q"].shape[1] if "joint_q" in self.data else 0
        self.joints = joints.split(",") if joints else []
        if len(self.joints) != ncols:
            self.joints = ["joint %d" % (j + 1) for j in range(ncols)]

    def col(self, key, j):
        return self.data[key][:, j]

    def title(self, what):
        suffix = "" if self.status == "completed" else "\n" + wrap("[status: %s]" % self.status)
        return "%s: %s%s" % (self.name, what, suffix)


def save(fig, outdir, name):
    path = os.path.join(outdir, name)
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


def plot_run(run, outdir):
    """G_joints.png, G_tip.png, G_energy.png for one run group."""
    g = run.name
    # Joints: q, v, tau.
    panels = [("joint_q", "q [rad or m]"), ("joint_v", "v [rad/s or m/s]"),
              ("joint_tau", "τ [N m or N]")]
    panels = [p for p in panels if p[0] in run.data]
    if panels:
        fig, axes = plt.subplots(len(panels), 1, sharex=True, figsize=(8, 2.6 * len(panels) + 0.8),
                                 squeeze=False)
        for ax, (key, ylabel) in zip(axes[:, 0], panels):
            for j, name in enumerate(run.joints):
                ax.plot(run.t, run.col(key, j), label=name)
            finish(ax, ylabel=ylabel)
        axes[-1, 0].set_xlabel("t [s]")
        axes[0, 0].set_title(run.title("joint coordinates, rates and torques"))
        fig.tight_layout()
        save(fig, outdir, "%s_joints.png" % g)
    # Tip deflections.
    if "tip_deflection" in run.data:
        fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7))
        for j, (ax, (name, ylabel)) in enumerate(zip(axes, TIP_LABELS)):
            y = run.col("tip_deflection", j)
            ax.plot(run.t, y, label=name, color="C%d" % j)
            if not np.any(y):
                ax.text(0.5, 0.75, "identically zero", transform=ax.transAxes, ha="center",
                        color="0.4")
            finish(ax, ylabel=ylabel)
        axes[-1].set_xlabel("t [s]")
        axes[0].set_title(run.title("tip deflections u1, u2 and torsion θ"))
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


def compare(ax, runs_cols, ylabel, xlabel=None):
    """Plot (run, key, column, label) series on one axis."""
    for k, (run, key, j, label) in enumerate(runs_cols):
        ax.plot(run.t, run.col(key, j), label=label, linestyle="-" if k == 0 else "--")
    finish(ax, xlabel, ylabel)


def status_note(*runs):
    bad = ["%s: %s" % (r.name, r.status) for r in runs if r.status != "completed"]
    return "\n" + wrap("[%s]" % "; ".join(bad)) if bad else ""


def plot_paper(runs, outdir):
    """The paper's Figures 5-8 from the rigid, kinematic and force groups."""
    rig, kin, frc = runs["rigid"], runs["kinematic"], runs["force"]
    # Fig. 5: tip deflections, kinematic vs force input.
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7.5))
    for j, (ax, (_, ylabel)) in enumerate(zip(axes, TIP_LABELS)):
        compare(ax, [(kin, "tip_deflection", j, "1: kinematic input"),
                     (frc, "tip_deflection", j, "2: force input")], ylabel)
    axes[-1].set_xlabel("t [s]")
    axes[0].set_title("Fig. 5: tip deflections u1, u2 and torsion θ of link 3"
                      + status_note(kin, frc))
    fig.tight_layout()
    save(fig, outdir, "fig5_tip.png")
    # Fig. 6: joint-3 torque, rigid vs flexible link.
    fig, ax = plt.subplots(figsize=(8, 4.5))
    compare(ax, [(rig, "joint_tau", 2, "rigid link 3"),
                 (kin, "joint_tau", 2, "flexible link 3 (kinematic input)")],
            "τ3 [N m]", "t [s]")
    ax.set_title("Fig. 6: joint-3 torque, rigid vs flexible link" + status_note(rig, kin))
    fig.tight_layout()
    save(fig, outdir, "fig6_torque3.png")
    # Fig. 7: joint-3 velocity, kinematic vs force input.
    fig, ax = plt.subplots(figsize=(8, 4.5))
    compare(ax, [(kin, "joint_v", 2, "1: kinematic input"),
                 (frc, "joint_v", 2, "2: force input")], "dψ3/dt [rad/s]", "t [s]")
    ax.set_title("Fig. 7: joint-3 velocity" + status_note(kin, frc))
    fig.tight_layout()
    save(fig, outdir, "fig7_velocity3.png")
    # Fig. 8: joint 1 and 2 accelerations, kinematic vs force input.
    fig, axes = plt.subplots(2, 1, sharex=True, figsize=(8, 6.5))
    for j, ax in enumerate(axes):
        compare(ax, [(kin, "joint_a", j, "1: kinematic input"),
                     (frc, "joint_a", j, "2: force input")], "d²ψ%d/dt² [rad/s²]" % (j + 1))
        ax.set_title("joint %d" % (j + 1), fontsize="medium")
    axes[-1].set_xlabel("t [s]")
    fig.suptitle("Fig. 8: joint 1 and 2 accelerations" + status_note(kin, frc))
    fig.tight_layout()
    save(fig, outdir, "fig8_accel12.png")


def plot_refine(group, outdir):
    """|value - reference| (or successive differences) against n, log-log, with fitted slope."""
    n = np.asarray(group["n"][:], dtype=float).ravel()
    v = np.asarray(group["value"][:], dtype=float).ravel()
    quantity = text_attr(group, "quantity", "value")
    if "reference" in group.attrs:
        ref = float(np.asarray(group.attrs["reference"]).ravel()[0])
        x, err = n, np.abs(v - ref)
        label, ylabel = "|value − reference|", "|%s − reference|" % quantity
        note = "reference (Richardson) = %.10g" % ref
    else:
        x, err = n[1:], np.abs(np.diff(v))
        label, ylabel = "|value[i] − value[i−1]|", "|Δ %s|" % quantity
        note = "no reference: successive differences"
    keep = (err > 0) & (x > 0) & np.isfinite(err)
    x, err = x[keep], err[keep]
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.loglog(x, err, "o-", label=label)
    if len(x) >= 2:
        lx, ly = np.log(x[-3:]), np.log(err[-3:])
        slope, icpt = np.polyfit(lx, ly, 1)
        xs = np.exp(np.linspace(lx[0], lx[-1], 20))
        ax.loglog(xs, np.exp(icpt) * xs ** slope, "k--",
                  label="fit, last %d points: slope %.2f" % (len(lx), slope))
    finish(ax, "n (number of rfes)", ylabel)
    ax.grid(True, which="minor", alpha=0.15)
    ax.set_xticks(x)
    ax.set_xticklabels(["%g" % v for v in x])
    ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    ax.set_title("Refinement study: %s\n%s" % (quantity, note), fontsize="medium")
    fig.tight_layout()
    save(fig, outdir, "refine_convergence.png")


def main(argv=None):
    parser = argparse.ArgumentParser(prog="rfem_plot.py", description=__doc__.splitlines()[0])
    parser.add_argument("result", metavar="RESULT.h5", help="HDF5 file written by rfem")
    parser.add_argument("-o", "--outdir", help="output directory (default: that of RESULT.h5)")
    args = parser.parse_args(argv)
    outdir = args.outdir or os.path.dirname(os.path.abspath(args.result))
    try:
        if not os.path.isfile(args.result):
            raise OSError("not a file" if os.path.exists(args.result) else "no such file")
        if not os.access(args.result, os.R_OK):
            raise OSError("permission denied")
        if not h5py.is_hdf5(args.result):
            raise OSError("not an HDF5 file")
        with h5py.File(args.result, "r") as f:
            groups = [k for k in f if isinstance(f[k], h5py.Group)]
            runs = {k: Run(f[k], k) for k in groups if "time" in f[k]}
            has_refine = "refine" in groups and "n" in f["refine"] and "value" in f["refine"]
            if not runs and not has_refine:
                raise ValueError("no run groups (with a `time` dataset) and no `refine` group")
            os.makedirs(outdir, exist_ok=True)
            if text_attr(f, "procedure") == "paper" and all(
                    g in runs for g in ("rigid", "kinematic", "force")):
                plot_paper(runs, outdir)
            for run in runs.values():
                plot_run(run, outdir)
            if has_refine:
                plot_refine(f["refine"], outdir)
    except (OSError, KeyError, ValueError, IndexError, TypeError) as exc:
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        print("rfem plot: error: %s: %s" % (args.result, reason), file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
