"""rfem.animate: the arm of a run moving — the base as a polyline through the joint origins, every
link's elastic axis through its rfes (deflection magnified by scale, shown in the title), its
payloads on the magnified axis, the trace of the last link's tip — drawn with matplotlib into MP4
(Debian's ffmpeg) or GIF (Pillow). Reads the poses a run stores every
simulation.store_flexible_every outputs (axis_position, axis_deflection; docs/results.md).

From Python (the module is callable: rfem.animate(...) writes the film, as `rfem animate`):

    rfem.animate("arm.h5", output="arm.gif", frames=50)    # the path written
    from rfem import animate
    animate.frame("arm.h5", t=0.5, view="xz", ax=ax)        # one pose onto your Axes; the Figure
    anim = animate.animation("arm.h5", frames=20)          # a matplotlib FuncAnimation
    HTML(anim.to_jshtml())                                 # inline in Jupyter, no ffmpeg needed

From the shell (what `rfem animate` runs):

    python3 -m rfem.animate RESULT.h5 [-o FILE.mp4|.gif] [--run force] [--scale K] [--view 3d|xy|xz|yz] [--fps 25]
"""
import argparse
import os
import shutil
import sys
import types

import h5py
import numpy as np

__all__ = ["AnimateError", "Poses", "frame", "animation", "write", "main"]

VIEWS = ("3d", "xy", "xz", "yz")
PLANES = {"xy": (0, 1), "xz": (0, 2), "yz": (1, 2)}


class AnimateError(RuntimeError):
    """What `rfem animate` cannot draw or write: the program's one-line message."""


def _text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


class Poses:
    """The stored poses of one run of a results file, read into memory: .run, .case, .links (the
    model's order: the last is the tip's), .t (the stored steps' times), .pos and .dfl per link
    (steps × points × 3: the elastic axis and its deflection), .base (output rows × joints × 3),
    .payloads per link (output rows × payloads × 3), .tip (output rows × 3), .out_row (the output
    row of each stored step), .size (the arm's extent) and .peak (its largest deflection)."""

    def __init__(self, results, run=None):
        path = os.fspath(results)
        try:
            f = h5py.File(path, "r", swmr=True)
        except OSError:
            raise AnimateError("%s: not a readable HDF5 results file" % path) from None
        with f:
            runs = [g for g in f if isinstance(f[g], h5py.Group) and "flexible_time" in f[g]]
            if run and run not in f:
                raise AnimateError("%s: no run '%s'" % (path, run))
            if not runs:
                raise AnimateError("%s: no run stores poses (run with simulation.store_flexible_every > 0)" % path)
            if run and run not in runs:
                raise AnimateError("%s: run %s stores no poses (run with simulation.store_flexible_every > 0)"
                                   % (path, run))
            self.run = run or runs[-1]
            g = f[self.run]
            order = [_text(n) for n in g.attrs.get("link_names", [])]
            self.links = sorted((l for l in g["links"] if "axis_position" in g["links"][l]),
                                key=lambda l: order.index(l) if l in order else len(order))
            self.t = g["flexible_time"][:, 0]
            self.t_out = g["time"][:, 0]
            steps, outs = len(self.t), len(self.t_out)
            self.pos = {l: g["links"][l]["axis_position"][()].reshape(steps, -1, 3) for l in self.links}
            self.dfl = {l: g["links"][l]["axis_deflection"][()].reshape(steps, -1, 3) for l in self.links}
            self.out_row = np.minimum(np.searchsorted(self.t_out, self.t - 1e-12), outs - 1)
            self.base = g["joint_position"][()].reshape(outs, -1, 3) if "joint_position" in g else None
            self.payloads = {l: g["links"][l]["payload_position"][()].reshape(outs, -1, 3)
                             for l in self.links if "payload_position" in g["links"][l]}
            self.tip_name = self.links[-1]
            self.tip = g["links"][self.tip_name]["tip_position"][()]
            self.case = os.path.basename(_text(f.attrs.get("case_path", "")))
        allp = np.concatenate([p.reshape(-1, 3) for p in self.pos.values()] +
                              ([self.base.reshape(-1, 3)] if self.base is not None else []))
        self.lo, self.hi = allp.min(axis=0), allp.max(axis=0)
        self.size = float(np.max(self.hi - self.lo)) or 1.0
        self.peak = max(float(np.max(np.abs(d))) for d in self.dfl.values())

    def default_scale(self):
        """The magnification that draws the peak deflection at 10 % of the arm's size."""
        return max(1.0, round(0.1 * self.size / self.peak)) if self.peak > 0 else 1.0

    def axis(self, link, step, scale):
        """The link's elastic axis at a stored step with its deflection magnified `scale` times."""
        return self.pos[link][step] + (scale - 1) * self.dfl[link][step]

    def payload(self, link, step, scale):
        """The link's payloads at a stored step, each on the magnified axis: moved by (scale − 1)
        times the axis' deflection where it sits (at the tip: the magnified tip)."""
        p = self.payloads[link][self.out_row[step]]
        axis, d = self.pos[link][step], self.dfl[link][step]
        if len(axis) < 2:
            return p
        out = np.empty_like(p)
        for k, point in enumerate(p):
            # the nearest point of the (true) axis polyline, and the deflection interpolated there
            a, b = axis[:-1], axis[1:]
            ab = b - a
            s = np.clip(np.einsum("ij,ij->i", point - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300), 0, 1)
            near = a + s[:, None] * ab
            i = int(np.argmin(np.einsum("ij,ij->i", near - point, near - point)))
            out[k] = point + (scale - 1) * ((1 - s[i]) * d[i] + s[i] * d[i + 1])
        return out


def _poses(results, run):
    return results if isinstance(results, Poses) else Poses(results, run)


def _check(view, scale):
    if view not in VIEWS:
        raise AnimateError("view: one of %s (got %r)" % (", ".join(VIEWS), view))
    if scale is not None and not (np.isfinite(scale) and scale > 0):
        raise AnimateError("--scale must be a positive number")


class _Drawing:
    """The artists of one view of the arm on an Axes, and how to move them to a stored step."""

    def __init__(self, poses, ax, view, scale, title=None):
        self.poses, self.ax, self.view, self.K = poses, ax, view, scale
        lo, hi, size = poses.lo, poses.hi, poses.size
        if view == "3d":
            c = (lo + hi) / 2
            for setlim, k in ((ax.set_xlim, 0), (ax.set_ylim, 1), (ax.set_zlim, 2)):
                setlim(c[k] - 0.6 * size, c[k] + 0.6 * size)
            ax.set_xlabel("x [m]"); ax.set_ylabel("y [m]"); ax.set_zlabel("z [m]")
            self.proj = lambda p: (p[..., 0], p[..., 1], p[..., 2])
        else:
            i, j = PLANES[view]
            pad = 0.1 * size
            ax.set_xlim(lo[i] - pad, hi[i] + pad); ax.set_ylim(lo[j] - pad, hi[j] + pad)
            ax.set_aspect("equal"); ax.grid(alpha=0.3)
            ax.set_xlabel("xyz"[i] + " [m]"); ax.set_ylabel("xyz"[j] + " [m]")
            self.proj = lambda p: (p[..., i], p[..., j])
        proj = self.proj
        self.base_line, = ax.plot(*proj(np.zeros((2, 3))), "-o", color="0.3", lw=3, ms=4, label="base (joint origins)")
        self.link_lines = {l: ax.plot(*proj(np.zeros((2, 3))), "-", lw=2, label="link %s" % l)[0] for l in poses.links}
        self.pay_pts = {l: ax.plot(*proj(np.zeros((1, 3))), "s", color="k", ms=6,
                                   label="payload%s of %s" % ("s" if poses.payloads[l].shape[1] > 1 else "", l))[0]
                        for l in poses.payloads}
        self.trace, = ax.plot(*proj(np.zeros((1, 3))), ":", color="C3", lw=1, label="tip of %s" % poses.tip_name)
        ax.legend(loc="upper right", fontsize=8)
        self.title = title if title is not None else ax.set_title("", fontsize="medium")

    def _set(self, line, p):
        xy = self.proj(p)
        line.set_data(xy[0], xy[1])
        if self.view == "3d":
            line.set_3d_properties(xy[2])

    def draw(self, r):
        P, K = self.poses, self.K
        o = P.out_row[r]
        if P.base is not None:
            self._set(self.base_line, np.vstack([np.zeros((1, 3)), P.base[o]]))  # from the origin of {0}
        for l in P.links:
            self._set(self.link_lines[l], P.axis(l, r, K))
        for l in P.payloads:
            self._set(self.pay_pts[l], P.payload(l, r, K))
        self._set(self.trace, P.tip[: o + 1])
        self.title.set_text("%s, run %s: t = %.3f s (deflection ×%g)" % (P.case, P.run, P.t[r], K))


def _new_axes(fig, view):
    if fig is None:
        from .plots import new_figure
        fig = new_figure(figsize=(7.2, 5.4), dpi=100)
    return fig.add_subplot(projection="3d") if view == "3d" else fig.add_subplot()


def frame(results, t=None, step=None, run=None, scale=None, view="3d", ax=None):
    """One pose of the arm — the stored step nearest to time t [s] (or index `step`; default the
    last) — drawn onto `ax` (for view "3d" an Axes with projection="3d"), or onto a new Figure.
    results: a results file's path or a Poses. Returns the Figure."""
    _check(view, scale)
    P = _poses(results, run)
    if step is None:
        step = len(P.t) - 1 if t is None else int(np.argmin(np.abs(P.t - t)))
    if not -len(P.t) <= step < len(P.t):
        raise AnimateError("step: the run stored %d poses (got %d)" % (len(P.t), step))
    if ax is None:
        ax = _new_axes(None, view)
    drawing = _Drawing(P, ax, view, scale if scale is not None else P.default_scale())
    drawing.draw(step % len(P.t))
    return ax.figure


def _rows(P, frames):
    return np.unique(np.linspace(0, len(P.t) - 1, min(frames, len(P.t))).round().astype(int))


def animation(results, run=None, scale=None, view="3d", frames=300, fps=25, fig=None, progress=None):
    """The arm moving as a matplotlib FuncAnimation over at most `frames` stored steps (thinned
    evenly), on `fig` or a new Figure: anim.save(...), or in Jupyter HTML(anim.to_jshtml()).
    progress(k, count) is called as each frame is drawn."""
    _check(view, scale)
    if frames <= 1 or fps <= 0:
        raise AnimateError("--fps must be positive and --frames at least 2")
    from matplotlib import animation as mpl_animation
    P = _poses(results, run)
    rows = _rows(P, frames)
    ax = _new_axes(fig, view)
    drawing = _Drawing(P, ax, view, scale if scale is not None else P.default_scale(),
                       title=ax.figure.suptitle(""))

    def draw(k):
        drawing.draw(rows[k])
        if progress:
            progress(k + 1, len(rows))
        return []

    anim = mpl_animation.FuncAnimation(ax.figure, draw, frames=len(rows), init_func=lambda: [], interval=1000.0 / fps,
                                       blit=False)
    anim.frames, anim.scale, anim.run = len(rows), drawing.K, P.run
    return anim


def write(results, output=None, run=None, scale=None, view="3d", fps=25, frames=300, progress=None):
    """Writes the film: MP4 (ffmpeg) or GIF by the output's extension (default RESULT.RUN.mp4,
    .gif without ffmpeg), whole or not at all. Returns (path, frames, scale)."""
    if fps <= 0 or frames <= 1:
        raise AnimateError("--fps must be positive and --frames at least 2")
    _check(view, scale)
    results = os.fspath(results)
    P = _poses(results, run)
    out = os.fspath(output) if output else None
    ffmpeg = shutil.which("ffmpeg") is not None
    if not out:
        out = os.path.splitext(results)[0] + ".%s.%s" % (P.run, "mp4" if ffmpeg else "gif")
    ext = os.path.splitext(out)[1].lower()
    if ext not in (".mp4", ".gif"):
        raise AnimateError("%s: write .mp4 or .gif" % out)
    if ext == ".mp4" and not ffmpeg:
        raise AnimateError("%s: MP4 needs ffmpeg (apt-get install ffmpeg), or write a .gif" % out)
    from matplotlib import animation as mpl_animation
    anim = animation(P, scale=scale, view=view, frames=frames, fps=fps, progress=progress)
    writer = mpl_animation.FFMpegWriter(fps=fps) if ext == ".mp4" else mpl_animation.PillowWriter(fps=fps)
    part = out + ".part" + ext
    try:
        anim.save(part, writer=writer)
    except Exception as e:  # a write failure: no half file left behind
        if os.path.exists(part):
            os.remove(part)
        raise AnimateError("%s: cannot write: %s" % (out, e)) from e
    os.replace(part, out)
    return out, anim.frames, anim.scale


class _CallableModule(types.ModuleType):
    """rfem.animate is this module and, called, writes the film as rfem.animate(...) always did."""

    def __call__(self, results, output=None, run=None, scale=None, view="3d", fps=25, frames=300):
        """The arm of a run moving (`rfem animate`): MP4 (ffmpeg) or GIF by the output's extension
        (default RESULT.RUN.mp4, .gif without ffmpeg); scale magnifies the deflections (default: the
        peak drawn at 10 % of the arm); view 3d, xy, xz or yz. Needs a run that stored its poses
        (simulation.store_flexible_every > 0). Returns the path written; errors raise AnimateError
        (a RuntimeError) with the program's one-line message."""
        return write(results, output=output, run=run, scale=scale, view=view, fps=fps, frames=frames)[0]


sys.modules[__name__].__class__ = _CallableModule


def main(argv=None):
    """`rfem animate` (python3 -m rfem.animate RESULT.h5 …): "wrote FILE (N frames, deflection ×K)";
    what it cannot do: one line "rfem animate: error: …" on stderr, exit code 2. Frame counts
    ("\\r…") on stderr when it is a terminal."""
    ap = argparse.ArgumentParser(prog="rfem animate", description=__doc__.split("\n\n")[0])
    ap.add_argument("results")
    ap.add_argument("-o", "--output", help="MP4 or GIF file (default: RESULT.RUN.mp4, .gif without ffmpeg)")
    ap.add_argument("--run", help="run group (default: the last run that stored poses)")
    ap.add_argument("--scale", type=float, default=None, help="deflection magnification (default: 10%% of the arm's size at the peak)")
    ap.add_argument("--view", choices=list(VIEWS), default="3d")
    ap.add_argument("--fps", type=int, default=25)
    ap.add_argument("--frames", type=int, default=300, help="at most this many frames (stored steps are thinned evenly)")
    a = ap.parse_args(argv)
    tty = sys.stderr.isatty()
    progress = (lambda k, count: sys.stderr.write("\rrfem animate: frame %d of %d" % (k, count))) if tty else None
    try:
        if a.fps <= 0 or a.frames <= 1:
            raise AnimateError("--fps must be positive and --frames at least 2")
        out, count, scale = write(a.results, a.output, a.run, a.scale, a.view, a.fps, a.frames, progress)
    except AnimateError as e:
        if tty:
            sys.stderr.write("\r\033[K")  # the progress line, if any
        sys.stderr.write("rfem animate: error: %s\n" % e)
        return 2
    if tty:
        sys.stderr.write("\n")
    print("wrote %s (%d frames, deflection ×%g)" % (out, count, scale))
    return 0


if __name__ == "__main__":
    sys.exit(main())
