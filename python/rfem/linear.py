"""Linear models of rfem (rfem.linearize, `rfem linearize -o LIN.h5`): frequency responses, modes
and Bode plots, from a model in memory or its file. `rfem bode` is `python3 -m rfem.linear`.

    G(j2πf) = (Cq + jω Cv − ω² Ca) (K + jω D − ω² M)⁻¹ B        (docs/formulation.md §8)

one sparse N×N complex solve per frequency (the second-order form; no 2N first-order system)."""
import argparse
import os
import sys

import numpy as np


class LinearError(RuntimeError):
    """A linear model file rfem cannot read, or an input or output it does not have (one line)."""


class LinearFile:
    """The group `linear` of a file `rfem linearize -o` (or rfem.linearize(output=…)) wrote, with the
    attributes of an rfem.LinearModel: M, D, K, B, Cq, Cv, Ca, states, inputs, outputs, output_units,
    t, equilibrium."""

    def __init__(self, path):
        import h5py
        self.path = os.fspath(path)
        try:
            with h5py.File(self.path, "r") as f:
                if "linear" not in f:
                    raise LinearError(f"{self.path}: no linear model (group linear; write one with rfem linearize -o)")
                g = f["linear"]
                text = lambda v: [x.decode() if isinstance(x, bytes) else str(x) for x in v]  # noqa: E731
                self.states = text(g.attrs["states"])
                self.inputs = [] if text(g.attrs["inputs"]) == ["(none)"] else text(g.attrs["inputs"])
                self.outputs = text(g.attrs["outputs"])
                self.output_units = text(g.attrs["output_units"])
                for name in ("M", "D", "K", "B", "Cq", "Cv", "Ca"):
                    if name == "B" and "B" not in g:  # (every joint prescribed: no inputs)
                        setattr(self, name, _sparse(np.zeros((len(self.states), 0))))
                        continue
                    d = g[name]
                    if "matrix_columns" in d.attrs:  # sparse: (row, column, value), 0-based
                        import scipy.sparse as sp
                        t = d[()]
                        shape = (len(d.attrs["rows"]), len(d.attrs["matrix_columns"]))
                        _check_triplets(self.path, name, t, shape)
                        setattr(self, name, sp.csc_matrix((t[:, 2], (t[:, 0].astype(int), t[:, 1].astype(int))), shape=shape))
                    else:  # a table (older files held M, D, K, B as tables too)
                        a = d[()]
                        bad = np.argwhere(~np.isfinite(a))
                        if len(bad):
                            raise LinearError(f"{self.path}: linear/{name}: entry {tuple(int(i) for i in bad[0])} is not finite "
                                              f"({len(bad)} such): a damaged file (write it again with rfem linearize -o)")
                        setattr(self, name, _sparse(a) if name in ("M", "D", "K", "B") else a)
                about = g.attrs["about"]
                self.equilibrium = (about.decode() if isinstance(about, bytes) else str(about)) == "equilibrium"
                t = g.attrs["t"]
                self.t = float(t.decode() if isinstance(t, bytes) else t)
        except (OSError, KeyError) as e:
            raise LinearError(f"{self.path}: not a linear model file rfem wrote ({e})") from None

    def __repr__(self):
        return (f"<rfem.linear.LinearFile {self.path}: {len(self.states)} states, {len(self.inputs)} inputs, "
                f"{len(self.outputs)} outputs>")


def _check_triplets(path, name, t, shape):
    """A sparse matrix's (row, column, value) triplets: whole, in range, finite; else one LinearError line."""
    if t.ndim != 2 or t.shape[1] != 3:
        raise LinearError(f"{path}: linear/{name}: not a table of (row, column, value) triplets")
    for k, what in ((0, "row"), (1, "column")):
        i = t[:, k]
        ok = np.isfinite(i) & (i == np.round(i)) & (i >= 0) & (i < shape[k])
        if not ok.all():
            j = int(np.argmin(ok))
            raise LinearError(f"{path}: linear/{name}: triplet {j} has {what} index {i[j]!r}, not a whole number "
                              f"from 0 to {shape[k] - 1}: a damaged file (write it again with rfem linearize -o)")
    bad = np.flatnonzero(~np.isfinite(t[:, 2]))
    if len(bad):
        j = int(bad[0])
        raise LinearError(f"{path}: linear/{name}: the value at ({int(t[j, 0])}, {int(t[j, 1])}) is not finite "
                          f"({len(bad)} such): a damaged file (write it again with rfem linearize -o)")


def _sparse(a):
    import scipy.sparse as sp
    return sp.csc_matrix(a)


def _model(lin):
    return LinearFile(lin) if isinstance(lin, (str, bytes, os.PathLike)) else lin


def _index(names, name, what):
    if isinstance(name, (int, np.integer)):
        if not 0 <= name < len(names):
            raise LinearError(f"{what}: no {what} number {name} (0 to {len(names) - 1})")
        return int(name)
    if name not in names:
        raise LinearError(f"{what}: no {what} named {name!r} (have: {', '.join(names) or 'none'})")
    return names.index(name)


def frequency_response(lin, frequencies, input=None, output=None):
    """G(j2πf) for f in `frequencies` [Hz]: complex, shape (len f, outputs, inputs), or (len f,) for
    one `input` and `output` (names or numbers). Units: the output's per the input's (m per N m, …).
    `lin`: an rfem.LinearModel, a LinearFile or the path of a linear model file."""
    lin = _model(lin)
    f = np.atleast_1d(np.asarray(frequencies, dtype=float))
    if not np.isfinite(f).all() or (f < 0).any():
        raise LinearError("frequencies: must be finite and 0 or more [Hz]")
    ins = slice(None) if input is None else [_index(lin.inputs, input, "input")]
    outs = slice(None) if output is None else [_index(lin.outputs, output, "output")]
    import scipy.sparse.linalg as sla
    M, D, K = (_sparse(x) for x in (lin.M, lin.D, lin.K))
    B = _sparse(lin.B)[:, ins].toarray()
    Cq, Cv, Ca = lin.Cq[outs], lin.Cv[outs], lin.Ca[outs]
    G = np.empty((len(f), Cq.shape[0], B.shape[1]), dtype=complex)
    for k, fk in enumerate(f):
        w = 2 * np.pi * fk
        X = sla.splu((K + 1j * w * D - w * w * M).astype(complex).tocsc(), permc_spec="NATURAL", diag_pivot_thresh=0.01,
                     options=dict(SymmetricMode=True)).solve(B.astype(complex))
        G[k] = (Cq + 1j * w * Cv - w * w * Ca) @ X
    return G[:, 0, 0] if input is not None and output is not None else G


def modes(lin, count=12):
    """The first-order model's lowest `count` modes: (frequencies [Hz], damping ratios), ascending,
    one per oscillating pair of eigenvalues of A (ω > 0) — as `rfem linearize` prints them and
    LinearModel.modes gives them (dense up to 16 states, else shift-invert Arnoldi on the sparse
    pencil K + σD + σ²M: dense QR loses the lowest ones' digits to ‖A‖ ~ the highest ω²)."""
    from . import _rfem
    lin = _model(lin)
    M, D, K = (_sparse(x).astype(float) for x in (lin.M, lin.D, lin.K))
    m = _rfem._linear_modes(M, D, K, int(count))
    return np.array([x[0] for x in m]), np.array([x[1] for x in m])


def bode(lin, input, output, frequencies=None, fig=None, marks=6):
    """Magnitude and phase of G(j2πf) from `input` to `output` (names) on log axes, the model's
    lowest `marks` modes marked; onto `fig` (an empty Figure) or a new one. Default frequencies:
    600 log-spaced from a tenth of the lowest mode to three times the `marks`-th. Returns the Figure."""
    from . import plots
    lin = _model(lin)
    fm, zeta = modes(lin)
    if frequencies is None:
        lo = fm[0] / 10 if len(fm) else 0.1
        hi = 3 * fm[min(marks, len(fm)) - 1] if len(fm) else 100.0
        frequencies = np.logspace(np.log10(lo), np.log10(hi), 600)
    G = frequency_response(lin, frequencies, input, output)
    own = fig is None
    if own:
        fig = plots.new_figure((7.5, 6))
    mag, ph = fig.subplots(2, 1, sharex=True)
    k_out = _index(lin.outputs, output, "output")
    mag.loglog(frequencies, np.abs(G), color="C0")
    ph.semilogx(frequencies, np.degrees(np.unwrap(np.angle(G))), color="C0")
    for i, (f, z) in enumerate(zip(fm[:marks], zeta[:marks])):
        for ax in (mag, ph):
            ax.axvline(f, color="0.6", lw=0.8, ls=":", label=f"mode {i + 1}: {f:.4g} Hz, ζ = {z:.3g}" if ax is mag else None)
    tau = f"{input}/tau"
    unit_in = lin.output_units[lin.outputs.index(tau)] if tau in lin.outputs else "N m"
    mag.set_ylabel(f"|G| [{lin.output_units[k_out]} / {unit_in}]")
    ph.set_ylabel("phase [deg]")
    ph.set_xlabel("frequency [Hz]")
    mag.set_title(f"frequency response {input} → {output} (about {'rest' if lin.equilibrium else 'the motion'} at t = {lin.t:g} s)")
    mag.legend(fontsize=7, loc="best")
    for ax in (mag, ph):
        ax.grid(True, which="both", alpha=0.3)
    return fig


def main(argv=None):
    """`rfem bode LIN.h5 --input J --output Y [-o FILE.png]`: the Bode plot of a linear model file; a
    line "wrote PATH" and the largest magnitude; a file or name it cannot use: one line
    "rfem bode: error: …" on stderr, exit code 2."""
    parser = argparse.ArgumentParser(prog="rfem bode", description=__doc__.splitlines()[0])
    parser.add_argument("linear", metavar="LIN.h5", help="a linear model file (rfem linearize -o)")
    parser.add_argument("--input", required=True, help="a free joint (the torque added there)")
    parser.add_argument("--output", required=True, help="an output, e.g. forearm/tip_u1, elbow/q, a sensor column")
    parser.add_argument("-o", "--out", help="the figure (default: LIN.INPUT.OUTPUT.png beside LIN.h5; .pdf, .svg by extension)")
    args = parser.parse_args(argv)
    try:
        lin = LinearFile(args.linear)
        _index(lin.inputs, args.input, "input")
        _index(lin.outputs, args.output, "output")
        fig = bode(lin, args.input, args.output)
        out = args.out or "%s.%s.%s.png" % (os.path.splitext(args.linear)[0], args.input, args.output.replace("/", "_"))
        fig.savefig(out, dpi=120)
        fm, _ = modes(lin)
        f = np.logspace(np.log10(fm[0] / 10), np.log10(3 * fm[min(6, len(fm)) - 1]), 600) if len(fm) else np.logspace(-1, 2, 600)
        G = np.abs(frequency_response(lin, f, args.input, args.output))
        print("wrote %s" % out)
        print("largest |G| = %.6g at %.6g Hz" % (G.max(), f[np.argmax(G)]))
    except (LinearError, OSError, ValueError, RuntimeError, ArithmeticError) as exc:  # (scipy's singular matrix too)
        print("rfem bode: error: %s" % str(exc).splitlines()[0], file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
