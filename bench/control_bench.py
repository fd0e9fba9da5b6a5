#!/usr/bin/python3
"""The cost of a controller in the loop: the PD law of paper_pd_tracking.toml (kp = 40, kd = 60 on
each joint, the deployment references, no feed-forward; a hub inertia of 0.5 kg m² on every joint:
without one, psi3 sees only the link's first rfe at high frequency and the sampled law is unstable)
at n = 60 over 20 s, one thread, four ways:

  continuous   the case's own pd law (rfem.run): the reference
  built-in     the case's pd law with sample_time = 1 ms (the integrator samples and holds it)
  C++ 1 kHz    rfem::run_controlled with a C++ callback (bench/control_bench.cpp)
  Python 1 kHz rfem.run_controlled with a Python callback
  chunks 1 ms  rfem.Simulation stepped from Python: snapshot, set_torque, advance(t + 1 ms)

Medians of --repeat runs; each line gives the wall time, its ratio to the C++ callback and to the
continuous law, the steps, and the distance of the peak tip deflections from the continuous law's
(the zero-order hold's effect, first order in the sample time). The Python overhead per call is
(Python − C++) / calls.

    /usr/bin/python3 bench/control_bench.py [--bench build/bench/rfem_control_bench] [--repeat 3] [--out bench/results/control.md]
"""
import argparse
import math
import os
import platform
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
import rfem  # noqa: E402

CASE = os.path.join(ROOT, "cases", "paper_pd_tracking.toml")
N, TS, KP, KD, ALPHA, T = 60, 1e-3, 40.0, 60.0, {"psi1": 0.5, "psi2": 0.75, "psi3": 1.0}, 15.0
DRIVE = "joints.*.drive={inertia=0.5}"


def reference(t, a):
    """Kane's deployment law from psi0 = pi (solvers/inputs.hpp, deployment_law): q, qd."""
    if t <= T:
        return (math.pi - math.pi * a / (2 * T) * (t - T / (2 * math.pi) * math.sin(2 * math.pi * t / T)),
                -math.pi * a / (2 * T) * (1 - math.cos(2 * math.pi * t / T)))
    return math.pi - math.pi * a / 2, 0.0


def pd(t, y):
    u = {}
    for j, a in ALPHA.items():
        q, qd = reference(t, a)
        u[j] = KP * (q - y["q"][j]) + KD * (qd - y["qd"][j])
    return u


def timed(f):
    t0 = time.perf_counter()
    r = f()
    return time.perf_counter() - t0, r


def peaks(run):
    d = run.table("tip_deflection")
    return abs(d).max(axis=0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--bench", default=os.path.join(ROOT, "build", "bench", "rfem_control_bench"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "control.md"))
    a = ap.parse_args()
    continuous = rfem.load(CASE, overrides=['joints.*.input.feedforward="none"', DRIVE])
    torque = rfem.load(CASE, overrides=['joints.*.input={kind="torque", value=0.0}', DRIVE])
    builtin = rfem.load(CASE, overrides=['joints.*.input.feedforward="none"', DRIVE, f"joints.*.input.sample_time={TS}"])
    rows = {}

    def chunks():
        sim = rfem.Simulation(torque, n=N, threads=1)
        k = 0
        while sim.time < sim.t_end:
            t = k * TS
            for j, tau in pd(t, sim.snapshot()).items():
                sim.set_torque(j, tau)
            k += 1
            sim.advance(min(k * TS, sim.t_end))
        return sim.finish()

    for _ in range(a.repeat):
        w, r = timed(lambda: rfem.run(continuous, n=N, threads=1)["run"])
        rows.setdefault("continuous pd", []).append((w, r.stats["steps"], peaks(r)))
        w, r = timed(lambda: rfem.run(builtin, n=N, threads=1)["run"])
        rows.setdefault("built-in digital pd, 1 kHz", []).append((w, r.stats["steps"], peaks(r)))
        out = subprocess.run([a.bench, CASE, str(N), str(TS), "1"], capture_output=True, text=True, check=True).stdout.split()
        rows.setdefault("C++ callback, 1 kHz", []).append((float(out[1]), int(out[5]), [float(out[7]), float(out[9]), float(out[11])]))
        w, r = timed(lambda: rfem.run_controlled(torque, pd, TS, n=N, threads=1))
        rows.setdefault("Python callback, 1 kHz", []).append((w, r.stats["steps"], peaks(r)))
        w, r = timed(chunks)
        rows.setdefault("Simulation.advance, 1 ms chunks (Python)", []).append((w, r.stats["steps"], peaks(r)))
    med = {k: statistics.median(x[0] for x in v) for k, v in rows.items()}
    ref = rows["continuous pd"][0][2]
    cpp = med["built-in digital pd, 1 kHz"]
    calls = round(20.0 / TS)
    lines = [f"# A controller in the loop: cost (bench/control_bench.py)", "",
             f"{platform.node()}, {os.cpu_count()} cores, {platform.processor() or platform.machine()}, one thread; "
             f"paper_pd_tracking.toml at n = {N}, 20 s, PD at {1 / TS:.0f} Hz ({calls} calls); medians of {a.repeat}.", "",
             "| variant | wall [s] | / built-in digital | / continuous | steps | peak u1, u2, θ − continuous (rel.) |",
             "|---|---|---|---|---|---|"]
    for k, v in rows.items():
        p = v[0][2]
        dist = max(abs(p[i] - ref[i]) / ref[i] for i in range(3))
        lines.append(f"| {k} | {med[k]:.3f} | {med[k] / cpp:.2f} | {med[k] / med['continuous pd']:.2f} | {v[0][1]} | {dist:.2e} |")
    lines += ["", f"Python overhead per controller call: {(med['Python callback, 1 kHz'] - med['C++ callback, 1 kHz']) / calls * 1e6:.1f} µs "
              f"(GIL taken per call, the snapshot built as dicts)."]
    text = "\n".join(lines) + "\n"
    print(text)
    with open(a.out, "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
