#!/usr/bin/python3
"""rfem animate: the arm of a run moving — the base as a polyline through the joint origins, every
link's elastic axis through its rfes (deflection magnified by --scale, shown in the title), payloads,
the trace of the last link's tip — drawn with matplotlib into MP4 (Debian's ffmpeg) or GIF (Pillow).
Reads the poses a run stores every simulation.store_flexible_every outputs (axis_position,
axis_deflection; docs/results.md).

  rfem animate RESULT.h5 [-o FILE.mp4|.gif] [--run force] [--scale K] [--view 3d|xy|xz|yz] [--fps 25]
"""
import argparse
import os
import shutil
import sys

import h5py
import numpy as np


def fail(msg):
    sys.stderr.write("rfem animate: error: %s\n" % msg)
    sys.exit(2)


def main():
    ap = argparse.ArgumentParser(prog="rfem animate", description=__doc__.split("\n\n")[0])
    ap.add_argument("results")
    ap.add_argument("-o", "--output", help="MP4 or GIF file (default: RESULT.RUN.mp4, .gif without ffmpeg)")
    ap.add_argument("--run", help="run group (default: the last run that stored poses)")
    ap.add_argument("--scale", type=float, default=None, help="deflection magnification (default: 10%% of the arm's size at the peak)")
    ap.add_argument("--view", choices=["3d", "xy", "xz", "yz"], default="3d")
    ap.add_argument("--fps", type=int, default=25)
    ap.add_argument("--frames", type=int, default=300, help="at most this many frames (stored steps are thinned evenly)")
    a = ap.parse_args()
    if a.fps <= 0 or a.frames <= 1:
        fail("--fps must be positive and --frames at least 2")
    if a.scale is not None and not (np.isfinite(a.scale) and a.scale > 0):
        fail("--scale must be a positive number")
    try:
        f = h5py.File(a.results, "r", swmr=True)
    except OSError:
        fail("%s: not a readable HDF5 results file" % a.results)
    runs = [g for g in f if isinstance(f[g], h5py.Group) and "flexible_time" in f[g]]
    if a.run and a.run not in f:
        fail("%s: no run '%s'" % (a.results, a.run))
    if not runs:
        fail("%s: no run stores poses (run with simulation.store_flexible_every > 0)" % a.results)
    if a.run and a.run not in runs:
        fail("%s: run %s stores no poses (run with simulation.store_flexible_every > 0)" % (a.results, a.run))
    run = a.run or runs[-1]
    g = f[run]
    order = [n.decode() if isinstance(n, bytes) else str(n) for n in g.attrs.get("link_names", [])]
    links = sorted((l for l in g["links"] if "axis_position" in g["links"][l]),
                   key=lambda l: order.index(l) if l in order else len(order))  # the model's order: the last is the tip's
    t_flex = g["flexible_time"][:, 0]
    t_out = g["time"][:, 0]
    rows = np.unique(np.linspace(0, len(t_flex) - 1, min(a.frames, len(t_flex))).round().astype(int))
    pos = {l: g["links"][l]["axis_position"][()].reshape(len(t_flex), -1, 3) for l in links}
    dfl = {l: g["links"][l]["axis_deflection"][()].reshape(len(t_flex), -1, 3) for l in links}
    out_row = np.searchsorted(t_out, t_flex - 1e-12)
    base = g["joint_position"][()].reshape(len(t_out), -1, 3) if "joint_position" in g else None
    pay = {l: g["links"][l]["payload_position"][()].reshape(len(t_out), -1, 3)
           for l in links if "payload_position" in g["links"][l]}
    tip_name = links[-1]
    tip = g["links"][tip_name]["tip_position"][()]
    # Extent of the arm and the default magnification: the peak deflection drawn at 10 % of the arm.
    allp = np.concatenate([p.reshape(-1, 3) for p in pos.values()] + ([base.reshape(-1, 3)] if base is not None else []))
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    size = float(np.max(hi - lo)) or 1.0
    peak = max(float(np.max(np.abs(d))) for d in dfl.values())
    K = a.scale if a.scale is not None else (max(1.0, round(0.1 * size / peak)) if peak > 0 else 1.0)
    case = f.attrs.get("case_path", "")
    case = os.path.basename(case.decode() if isinstance(case, bytes) else str(case))

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import animation

    axes = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}
    fig = plt.figure(figsize=(7.2, 5.4), dpi=100)
    if a.view == "3d":
        ax = fig.add_subplot(projection="3d")
        c = (lo + hi) / 2
        for setlim, k in ((ax.set_xlim, 0), (ax.set_ylim, 1), (ax.set_zlim, 2)):
            setlim(c[k] - 0.6 * size, c[k] + 0.6 * size)
        ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]"); ax.set_zlabel("z [m]")
        proj = lambda p: (p[..., 0], p[..., 1], p[..., 2])
    else:
        ax = fig.add_subplot()
        i, j = axes[a.view]
        pad = 0.1 * size
        ax.set_xlim(lo[i] - pad, hi[i] + pad); ax.set_ylim(lo[j] - pad, hi[j] + pad)
        ax.set_aspect("equal"); ax.grid(alpha=0.3)
        ax.set_xlabel("xyz"[i] + " [m]"); ax.set_ylabel("xyz"[j] + " [m]")
        proj = lambda p: (p[..., i], p[..., j])
    base_line, = ax.plot(*proj(np.zeros((2, 3))), "-o", color="0.3", lw=3, ms=4, label="base (joint origins)")
    link_lines = {l: ax.plot(*proj(np.zeros((2, 3))), "-", lw=2, label="link %s" % l)[0] for l in links}
    pay_pts = {l: ax.plot(*proj(np.zeros((1, 3))), "s", color="k", ms=6)[0] for l in pay}
    trace, = ax.plot(*proj(np.zeros((1, 3))), ":", color="C3", lw=1, label="tip of %s" % tip_name)
    ax.legend(loc="upper right", fontsize=8)
    title = fig.suptitle("")

    def set_data(line, p):
        xy = proj(p)
        line.set_data(xy[0], xy[1])
        if a.view == "3d":
            line.set_3d_properties(xy[2])

    def draw(k):
        r = rows[k]
        o = min(out_row[r], len(t_out) - 1)
        if base is not None:
            set_data(base_line, np.vstack([np.zeros((1, 3)), base[o]]))  # from the origin of {0}
        for l in links:
            set_data(link_lines[l], pos[l][r] + (K - 1) * dfl[l][r])
        for l in pay:
            set_data(pay_pts[l], pay[l][o])
        set_data(trace, tip[: o + 1])
        title.set_text("%s, run %s: t = %.3f s (deflection ×%g)" % (case, run, t_flex[r], K))
        sys.stderr.write("\rrfem animate: frame %d of %d" % (k + 1, len(rows)))
        return []

    out = a.output
    ffmpeg = shutil.which("ffmpeg") is not None
    if not out:
        out = os.path.splitext(a.results)[0] + ".%s.%s" % (run, "mp4" if ffmpeg else "gif")
    ext = os.path.splitext(out)[1].lower()
    if ext not in (".mp4", ".gif"):
        fail("%s: write .mp4 or .gif" % out)
    if ext == ".mp4" and not ffmpeg:
        fail("%s: MP4 needs ffmpeg (apt-get install ffmpeg), or write a .gif" % out)
    writer = animation.FFMpegWriter(fps=a.fps) if ext == ".mp4" else animation.PillowWriter(fps=a.fps)
    anim = animation.FuncAnimation(fig, draw, frames=len(rows), blit=False)
    try:
        anim.save(out + ".part" + ext, writer=writer)
    except Exception as e:  # a write failure: no half file left behind
        if os.path.exists(out + ".part" + ext):
            os.remove(out + ".part" + ext)
        sys.stderr.write("\n")
        fail("%s: cannot write: %s" % (out, e))
    os.replace(out + ".part" + ext, out)
    sys.stderr.write("\n")
    print("wrote %s (%d frames, deflection ×%g)" % (out, len(rows), K))


if __name__ == "__main__":
    main()
