#!/usr/bin/python3
"""Work–precision study of rfem's time integrators.

For each case and n: a converged reference (ESDIRK547L2SA2 at rtol 1e-10, atol 1e-11; a second one
with ESDIRK43I6L2SA at the same tolerances bounds the reference's own error), then every integrator
configuration at every tolerance and thread count. The error of a series is
max |x − x_ref| / max |x_ref| over the output times, for the tip deflections u1, u2, the torsion θ
and the torque of the last joint (τ3 of the paper's arm, τ1 of the spin-up hub; under force input
the torque is the applied one, so only u1, u2, θ count). Wall time is the integration's own
(`wall_time_s` of `rfem run --json`). Writes work_precision.md (tables), .csv and .png.

  /usr/bin/python3 bench/work_precision.py                         # the README's study (~1 h)
  /usr/bin/python3 bench/work_precision.py --ns 60 --threads 1     # a quick look
  /usr/bin/python3 bench/work_precision.py --cases deployment --ns 60 --threads 1 \
      --configs esdirk5,bdf2 --solvers chain,cholmod --name solvers   # integrator × linear solver
--solvers: the Newton matrix's factorisation ([simulation] linear_solver: rfem's chain solver or
CHOLMOD, the design card's path); every configuration runs with each, named "CONFIG+SOLVER" when
more than one is given. --name: the output files' stem (NAME.md, NAME.csv, NAME.png).
"""
import argparse
import csv
import json
import os
import subprocess
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
CASES = {
    "deployment": (os.path.join(ROOT, "cases", "paper_deployment.toml"), ["kinematic", "force"]),
    "spinup": (os.path.join(ROOT, "cases", "kane_spinup.toml"), ["run"]),
}
DEFAULT_CONFIGS = [
    ("esdirk5", ['simulation.integrator="esdirk"', 'simulation.method="ESDIRK547L2SA2_7_4_5"'], [1e-6, 1e-7, 1e-8, 1e-9]),
    ("esdirk4", ['simulation.integrator="esdirk"', 'simulation.method="ESDIRK43I6L2SA_6_3_4"'], [1e-6, 1e-7, 1e-8]),
    ("bdf2", ['simulation.integrator="bdf"'], [1e-6, 1e-7, 1e-8]),
]


def rfem_run(rfem, case, n, sets, out, threads, timeout):
    cmd = [rfem, "--threads", str(threads), "run", case, "--n", str(n), "--json", "-o", out]
    for s in sets:
        cmd += ["--set", s]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None
    if p.returncode != 0:
        sys.stderr.write(p.stderr)
        return None
    return json.loads(p.stdout)


def tolerances(rtol):
    # atol on coordinates well below the tip deflections; atol on velocities loose enough that the
    # undamped stiff sde modes are stepped over (their velocities dwarf their displacements).
    return [f"simulation.rtol={rtol}", f"simulation.atol={rtol * 1e-2}", "simulation.max_steps=10000000"]


def series(f, run):
    g = f[run]
    td = g["tip_deflection"][:]
    tau = g["joint_tau"][:]
    return {"u1": td[:, 0], "u2": td[:, 1], "theta": td[:, 2], "tau": tau[:, -1]}


def errors(f, ref, run):
    a, b = series(f, run), series(ref, run)
    return {k: float(np.abs(a[k] - b[k]).max() / max(np.abs(b[k]).max(), 1e-300)) for k in a}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rfem", default=os.path.join(ROOT, "build", "apps", "rfem"))
    ap.add_argument("--cases", default="deployment,spinup")
    ap.add_argument("--ns", default="60,600")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results"))
    ap.add_argument("--timeout", type=float, default=1800.0, help="per run [s]; slower runs are left out")
    ap.add_argument("--configs", default=",".join(c[0] for c in DEFAULT_CONFIGS), help="integrator configurations")
    ap.add_argument("--solvers", default="chain", help="linear solvers: chain, cholmod or both")
    ap.add_argument("--rtols", default=None, help="override every configuration's rtols (comma-separated)")
    ap.add_argument("--name", default="work_precision", help="stem of the output files")
    ap.add_argument("--replot", action="store_true", help="only rewrite the table and plot from OUT/NAME.csv")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    known = {c[0]: c for c in DEFAULT_CONFIGS}
    solvers = args.solvers.split(",")
    for x in solvers:
        if x not in ("chain", "cholmod"):
            sys.exit(f"work_precision: --solvers: unknown linear solver '{x}' (chain, cholmod)")
    configs = []
    for name in args.configs.split(","):
        if name not in known:
            sys.exit(f"work_precision: --configs: unknown configuration '{name}' ({', '.join(known)})")
        _, sets, rtols = known[name]
        if args.rtols:
            rtols = [float(x) for x in args.rtols.split(",")]
        for solver in solvers:
            label = name if len(solvers) == 1 else f"{name}+{solver}"
            configs.append((label, sets + [f'simulation.linear_solver="{solver}"'], rtols))
    if args.replot:
        with open(os.path.join(args.out, args.name + ".csv")) as fh:
            rows = [{k: (v if k in ("case", "run", "config") else float(v)) for k, v in r.items()} for r in csv.DictReader(fh)]
        for r in rows:
            for k in ("n", "threads", "steps", "residuals"):
                r[k] = int(r[k])
        write(rows, args.out, args.name)
        return
    rows = []
    for cname in args.cases.split(","):
        case, runs = CASES[cname]
        for n in [int(x) for x in args.ns.split(",")]:
            refs = {}
            for tag, method in (("A", "ESDIRK547L2SA2_7_4_5"), ("B", "ESDIRK43I6L2SA_6_3_4")):
                path = os.path.join(args.out, f"ref{tag}_{cname}_n{n}.h5")
                if not os.path.exists(path):
                    print(f"reference {tag}: {cname} n = {n} ...", flush=True)
                    # atol far below the tip deflections (~1e-2 m) but not below the stiff axial
                    # coordinates' round-off: tighter, the undamped axial modes must be resolved.
                    sets = ['simulation.integrator="esdirk"', f'simulation.method="{method}"', "simulation.rtol=1e-10",
                            "simulation.atol=1e-11", "simulation.max_steps=10000000"]
                    if not rfem_run(args.rfem, case, n, sets, path, 2, None):
                        sys.exit(f"reference {tag} failed")
                refs[tag] = h5py.File(path, "r")
            for run in runs:
                e = errors(refs["B"], refs["A"], run)
                print(f"{cname} n={n} {run}: reference error bound " + " ".join(f"{k}={v:.1e}" for k, v in e.items()))
                rows.append(dict(case=cname, n=n, run=run, config="reference B vs A", rtol=1e-10, threads=0, wall=np.nan,
                                 steps=0, residuals=0, **e))
            for cfg, sets, rtols in configs:
                for rtol in rtols:
                    for threads in [int(x) for x in args.threads.split(",")]:
                        out = os.path.join(args.out, "last.h5")
                        js = rfem_run(args.rfem, case, n, sets + tolerances(rtol), out, threads, args.timeout)
                        if not js:
                            print(f"{cname} n={n} {cfg} rtol={rtol:.0e} threads={threads}: failed or timed out", flush=True)
                            continue
                        f = h5py.File(out, "r")
                        for r in js["runs"]:
                            if r["name"] not in runs:
                                continue
                            e = errors(f, refs["A"], r["name"])
                            row = dict(case=cname, n=n, run=r["name"], config=cfg, rtol=rtol, threads=threads,
                                       wall=r["wall_time_s"], steps=r["steps"], residuals=r["residual_evals"], **e)
                            rows.append(row)
                            print(f"{cname} n={n} {r['name']:9} {cfg:8} rtol={rtol:.0e} threads={threads} "
                                  f"wall={row['wall']:.3f} s steps={row['steps']} residuals={row['residuals']} "
                                  + " ".join(f"{k}={row[k]:.1e}" for k in ("u1", "u2", "theta", "tau")), flush=True)
                        f.close()
            for r in refs.values():
                r.close()
    write(rows, args.out, args.name)


def write(rows, out, name="work_precision"):
    keys = ["case", "n", "run", "config", "rtol", "threads", "wall", "steps", "residuals", "u1", "u2", "theta", "tau"]
    with open(os.path.join(out, name + ".csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(out, name + ".md"), "w") as fh:
        fh.write("| case | n | run | integrator | rtol | threads | wall [s] | steps | residuals | u1 | u2 | θ | τ |\n")
        fh.write("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n")
        for r in rows:
            tau = "—" if r["run"] == "force" else f"{r['tau']:.1e}"
            wall = "—" if np.isnan(r["wall"]) else f"{r['wall']:.2f}"
            fh.write(f"| {r['case']} | {r['n']} | {r['run']} | {r['config']} | {r['rtol']:.0e} | {r['threads'] or '—'} | "
                     f"{wall} | {r['steps']} | {r['residuals']} | {r['u1']:.1e} | {r['u2']:.1e} | {r['theta']:.1e} | {tau} |\n")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    panels = sorted({(r["case"], r["n"], r["run"]) for r in rows})
    cols = min(3, len(panels))
    nrows = (len(panels) + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(4.6 * cols, 3.9 * nrows), squeeze=False)
    for ax in axes.ravel()[len(panels):]:
        ax.set_visible(False)
    for ax, (c, n, run) in zip(axes.ravel(), panels):
        for cfg in sorted({r["config"] for r in rows if not r["config"].startswith("reference")}):
            for th in sorted({r["threads"] for r in rows if r["threads"]}):
                pts = [r for r in rows if (r["case"], r["n"], r["run"], r["config"], r["threads"]) == (c, n, run, cfg, th)]
                if not pts:
                    continue
                err = [max(p["u1"], p["u2"], p["theta"], 0 if run == "force" else p["tau"]) for p in pts]
                ax.loglog([p["wall"] for p in pts], err, "o-" if th == 1 else "s--", label=f"{cfg}, {th} thr")
        ax.axhline(1e-4, color="grey", lw=0.8, ls=":")
        ax.set_title(f"{c} {run}, n = {n}", fontsize=9)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("max error of u1, u2, θ%s (relative)" % ("" if run == "force" else ", τ"))
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].legend(fontsize=7)
    fig.suptitle("rfem work–precision: error against a converged reference vs wall time (dotted: 1e-4)", fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(out, name + ".png"), dpi=110)


if __name__ == "__main__":
    main()
