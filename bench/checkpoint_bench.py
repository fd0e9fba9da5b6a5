#!/usr/bin/python3
"""The cost of checkpoints (rfem run --checkpoint): Kane's spin-up (t_end = 4 s) at n = 1 000 and
10 000 on --threads 2, run without checkpoints and with one after every step (--checkpoint 1e-9);
medians of `--repeat` runs. The difference over the steps is the cost of one checkpoint (flush the
rows, write 3 numbers per unknown, flush); at the default interval (5 s of wall time) a run pays
that once per 5 s: the fraction printed (target < 1 %). Also checks that the runs agree bit for bit.

    /usr/bin/python3 bench/checkpoint_bench.py [--rfem build/apps/rfem] [--repeat 3] [--out bench/results/checkpoint.md]
"""
import argparse
import os
import platform
import statistics
import subprocess
import tempfile
import time

import h5py
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_INTERVAL = 5.0  # s (studies/runs.hpp, kCheckpointInterval)


def run(rfem, n, checkpoint, cwd):
    out = os.path.join(cwd, f"c{n}_{checkpoint}.h5")
    cmd = [rfem, "--threads", "2", "run", os.path.join(ROOT, "cases", "kane_spinup.toml"), "--n", str(n), "-q",
           "--set", "simulation.t_end=4", "-o", out, "--checkpoint", str(checkpoint)]
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=dict(os.environ, OMP_WAIT_POLICY="PASSIVE"))
    wall = time.perf_counter() - t0
    with h5py.File(out) as f:
        steps = int(f["run"].attrs["steps"])
        tip = f["run/tip"][()]
        size = f["run/checkpoint"].shape[1] * 8
    os.remove(out)
    return wall, steps, tip, size


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rfem", default=os.path.join(ROOT, "build", "apps", "rfem"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ns", default="1000,10000")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "checkpoint.md"))
    a = ap.parse_args()
    lines = ["# Checkpoint cost (bench/checkpoint_bench.py)", "",
             f"Machine: {platform.machine()}, {os.cpu_count()} cores, {platform.platform()}; --threads 2; "
             f"Kane's spin-up, t_end = 4 s; medians of {a.repeat} runs.", "",
             "| n | run without [s] | with one per step [s] | steps | checkpoint [kB] | one checkpoint [ms] | "
             f"at the default {DEFAULT_INTERVAL:g} s interval | same results |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    with tempfile.TemporaryDirectory() as d:
        for n in [int(x) for x in a.ns.split(",")]:
            base, every = [], []
            for _ in range(a.repeat):
                w0, steps, tip0, _ = run(a.rfem, n, 0, d)
                w1, steps1, tip1, size = run(a.rfem, n, 1e-9, d)
                base.append(w0)
                every.append(w1)
            t0, t1 = statistics.median(base), statistics.median(every)
            one = max(t1 - t0, 0.0) / steps
            frac = one / DEFAULT_INTERVAL
            same = steps == steps1 and np.array_equal(tip0, tip1)
            lines.append(f"| {n} | {t0:.2f} | {t1:.2f} | {steps} | {size / 1024:.0f} | {one * 1e3:.3f} | "
                         f"{100 * frac:.4f} % | {'yes' if same else 'NO'} |")
            print(lines[-1], flush=True)
    lines += ["", "One checkpoint's cost is (with − without) / steps; a run at the default interval writes one per "
              f"{DEFAULT_INTERVAL:g} s of wall time, so it pays that cost / {DEFAULT_INTERVAL:g} s of its time."]
    with open(a.out, "w") as f:
        f.write("\n".join(lines) + "\n")
    print("written", a.out)


if __name__ == "__main__":
    main()
