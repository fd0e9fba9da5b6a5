#!/usr/bin/python3
"""The integrator's default tolerances, derived from the error they buy on every shipped case.

For each case that runs (cases/*.toml with dynamics) at its own n: a reference at rtol 1e-10,
atol 1e-12, atol_velocity 1e-7, then each candidate (rtol, atol, atol_velocity). The error of a series is
max |x − x_ref| / max |x_ref| over the output times; the series are every link's tip deflection
(u1, u2, θ — u1 and u2 share the larger of their peaks as scale, like the accuracy report), every
joint's torque and rate. A series whose peak is below 1e-12 of the largest of its kind is left out
(zero by symmetry). A candidate meets the promise when every series of every case is within 1e-4.
Writes a Markdown table to stdout (bench/results/default_tolerances.md is this output).

  /usr/bin/python3 bench/default_tolerances.py [--threads 1] [--candidates 1e-8/1e-10,1e-8/1e-8]
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import time

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
TIGHT = ["simulation.rtol=1e-10", "simulation.atol=1e-12", "simulation.atol_velocity=1e-7"]


def run(rfem, case, sets, out, threads):
    cmd = [rfem, "--threads", str(threads), "run", case, "--json", "-o", out, "--set", "simulation.max_steps=10000000"]
    for s in sets:
        cmd += ["--set", s]
    t0 = time.time()
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.stderr.write(f"{os.path.basename(case)}: {p.stderr}")
        return None, 0.0, 0
    js = json.loads(p.stdout)
    return js, time.time() - t0, sum(r["steps"] for r in js["runs"])


def series(f):
    out = {}
    for run in f:
        g = f[run]
        if not isinstance(g, h5py.Group) or "time" not in g:
            continue
        if "links" in g:
            for link in g["links"]:
                td = g["links"][link]["tip_deflection"][:]
                scale = max(np.abs(td[:, 0]).max(), np.abs(td[:, 1]).max())
                out[f"{run}/{link}/u1"] = (td[:, 0], scale)
                out[f"{run}/{link}/u2"] = (td[:, 1], scale)
                out[f"{run}/{link}/theta"] = (td[:, 2], np.abs(td[:, 2]).max())
        for ds, kind in (("joint_tau", "tau"), ("joint_v", "rate")):
            if ds in g and g[ds].shape[1] > 0:
                x = g[ds][:]
                for j in range(x.shape[1]):
                    out[f"{run}/{kind}{j + 1}"] = (x[:, j], np.abs(x[:, j]).max())
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rfem", default=os.path.join(ROOT, "build", "apps", "rfem"))
    ap.add_argument("--threads", default="1")
    ap.add_argument("--candidates", default="1e-8/1e-10/1e-5,1e-8/1e-8/1e-5,1e-8/1e-10/1e-7,1e-7/1e-10/1e-7,1e-6/1e-10/1e-7",
                    help="rtol/atol/atol_velocity, comma-separated")
    ap.add_argument("--cases", default=None, help="comma-separated case stems (default: every case that runs)")
    ap.add_argument("--work", default="/tmp/rfem_default_tolerances")
    ap.add_argument("--reuse", action="store_true", help="reuse the references already in --work")
    a = ap.parse_args()
    os.makedirs(a.work, exist_ok=True)
    cases = sorted(glob.glob(os.path.join(ROOT, "cases", "*.toml")))
    if a.cases:
        cases = [os.path.join(ROOT, "cases", c + ".toml") for c in a.cases.split(",")]
    cands = [c.split("/") for c in a.candidates.split(",")]
    print("| case | reference | " + " | ".join(f"{r}/{t}/{v}: worst series (error), time, steps" for r, t, v in cands) + " |")
    print("| --- | --- | " + " | ".join("---" for _ in cands) + " |")
    worst_all = [0.0] * len(cands)
    for case in cases:
        stem = os.path.splitext(os.path.basename(case))[0]
        ref_path = os.path.join(a.work, stem + "_ref.h5")
        if os.path.exists(ref_path) and a.reuse:
            wall, steps = float("nan"), "reused"
        else:
            js, wall, steps = run(a.rfem, case, TIGHT, ref_path, a.threads)
            if js is None or not js.get("runs"):
                continue
        with h5py.File(ref_path) as f:
            ref = series(f)
        biggest = {}
        for k, (x, s) in ref.items():
            kind = k.rsplit("/", 1)[1].rstrip("0123456789")
            biggest[kind] = max(biggest.get(kind, 0.0), s)
        cells = []
        for i, (rt, at, av) in enumerate(cands):
            path = os.path.join(a.work, f"{stem}_{rt}_{at}_{av}.h5")
            js, wall_c, steps_c = run(a.rfem, case, [f"simulation.rtol={rt}", f"simulation.atol={at}",
                                                     f"simulation.atol_velocity={av}"], path, a.threads)
            if js is None:
                cells.append("failed")
                continue
            worst, name = 0.0, ""
            with h5py.File(path) as f:
                got = series(f)
            for k, (x, s) in ref.items():
                kind = k.rsplit("/", 1)[1].rstrip("0123456789")
                if s < 1e-12 * biggest[kind] or s == 0.0:
                    continue
                e = float(np.abs(got[k][0] - x).max() / s)
                if e > worst:
                    worst, name = e, k
            worst_all[i] = max(worst_all[i], worst)
            cells.append(f"{name} ({worst:.1e}), {wall_c:.2f} s, {steps_c}")
        print(f"| {stem} | {wall:.1f} s, {steps} | " + " | ".join(cells) + " |", flush=True)
    print("| **worst** | | " + " | ".join(f"**{w:.1e}**" for w in worst_all) + " |")


if __name__ == "__main__":
    main()
