#!/usr/bin/python3
"""Sweep throughput and overhead (rfem sweep): the same 16-point sweep of Kane's spin-up (n = 300,
t_end = 4 s: ~1 s per point on one thread) run with --jobs 1 and 2, and under mpirun with 2, 3 and
5 ranks (1, 2 and 4 workers: the last oversubscribes a 2-core machine); medians of `--repeat` runs.
Prints points per second and the speed-up over --jobs 1, and the sweep machinery's overhead per
point: (the sweep's wall time − the sum of its runs' wall times) / points with --jobs 1, against the
mean run (target < 2 %).

    /usr/bin/python3 bench/sweep_bench.py [--rfem build/apps/rfem] [--repeat 3] [--out bench/results/sweep.md]
"""
import argparse
import os
import platform
import shutil
import statistics
import subprocess
import tempfile
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SWEEP = """[sweep]
case = "{root}/cases/kane_spinup.toml"
quantities = ["peak:u1"]
set = ["simulation.t_end=4"]
[parameters]
n = [300]
"joints.0.input.T" = {{ from = 10.0, to = 17.5, count = 16 }}
"""


def run(cmd, cwd):
    env = dict(os.environ, OMP_WAIT_POLICY="PASSIVE", OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for d in ("s.h5", "s.runs"):
        p = os.path.join(cwd, d)
        shutil.rmtree(p, ignore_errors=True) if os.path.isdir(p) else (os.path.exists(p) and os.remove(p))
    t0 = time.perf_counter()
    subprocess.run(cmd, cwd=cwd, env=env, check=True, capture_output=True)
    wall = time.perf_counter() - t0
    with h5py.File(os.path.join(cwd, "s.h5")) as f:
        runs = f["statistics"][()][:, 0]
        table = f["quantities"][()]
    return wall, runs, table


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rfem", default=os.path.join(ROOT, "build", "apps", "rfem"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out")
    a = ap.parse_args()
    rfem = os.path.abspath(a.rfem)
    work = tempfile.mkdtemp()
    with open(os.path.join(work, "s.toml"), "w") as f:
        f.write(SWEEP.format(root=ROOT))
    configs = [("--jobs 1", [rfem, "sweep", "s.toml", "-q", "--jobs", "1"]),
               ("--jobs 2", [rfem, "sweep", "s.toml", "-q", "--jobs", "2"])]
    if shutil.which("mpirun"):
        for p in (2, 3, 5):
            configs.append((f"mpirun -n {p} ({p - 1} worker{'s' if p > 2 else ''})",
                            ["mpirun", "-n", str(p), "--oversubscribe", rfem, "sweep", "s.toml", "-q"]))
    lines = [f"# rfem sweep: throughput and overhead", "",
             f"{platform.node()}, {os.cpu_count()} cores, {platform.processor() or platform.machine()}; 16 points of "
             f"Kane's spin-up (n = 300, t_end = 4 s), one thread per run; median of {a.repeat}", "",
             "| configuration | wall [s] | points/s | speed-up | overhead per point |", "| --- | --- | --- | --- | --- |"]
    base, ref, all_same = None, None, True
    for name, cmd in configs:
        results = [run(cmd, work) for _ in range(a.repeat)]
        wall = statistics.median(r[0] for r in results)
        if ref is None:
            ref = results[0][2]
        same = all(np.array_equal(r[2], ref) for r in results)
        all_same &= same
        if base is None:
            base = wall
            over = statistics.median((r[0] - r[1].sum()) / len(r[1]) / r[1].mean() for r in results)
            over_text = f"{100 * over:.2f} % of a {results[0][1].mean():.2f} s run"
        else:
            over_text = ""
        lines.append(f"| {name} | {wall:.2f} | {16 / wall:.2f} | {base / wall:.2f} | {over_text} |"
                     + ("" if same else " (table differs!)"))
        print(lines[-1], flush=True)
    lines += ["", "Every configuration gave the same table, bit for bit." if all_same else "TABLES DIFFER"]
    text = "\n".join(lines) + "\n"
    print(text)
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    shutil.rmtree(work)


if __name__ == "__main__":
    main()
