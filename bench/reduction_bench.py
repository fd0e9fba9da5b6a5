#!/usr/bin/python3
"""Work and precision of reduced links (README, "Reduced links"; docs/formulation.md §9): the paper's
procedure (cases/paper_deployment.toml) with link 3 kept whole and reduced to m modes, at one n and
thread count. Per m and run (kinematic, force): the median wall time over --repeat runs, steps,
residual evaluations, the ratio of the wall time to the full model's kinematic run at the default
tolerances (what a reduced link is for: force input at about the kinematic run's cost; the aim
is ≤ 1.5×), and the peaks of u1, u2, θ against the
full model's at the default tolerances (relative).
--modes: m or m:p (p: the static derivatives of the first p modes, link.derivatives; README
"Reduced links").
--atol: absolute tolerances [m, rad] to run every configuration at (simulation.atol; default
1e-10), each optionally with a relative one: 1e-5/1e-3 sets simulation.rtol = 1e-3 too (the case's
rtol otherwise). The steps of a force run are set by it, not by rtol: the rfe coordinates oscillate about
zero, where rtol·|q| is nothing (docs/performance.md, "Reduced links").

  /usr/bin/python3 bench/reduction_bench.py [--n 1000] [--modes 4,8,16,8:6] [--atol 1e-10,1e-8,1e-5/1e-3] [--threads 2]
      [--repeat 3] [--set key=value …]
Threads are pinned with OMP_PROC_BIND=close OMP_PLACES=cores.
"""
import argparse, json, os, statistics, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "paper_deployment.toml")


def parse_config(x):
    m, _, p = x.partition(":")
    return int(m), int(p or 0)


def label(mp):
    m, p = mp
    return "full" if not m else f"{m}" if not p else f"{m}:{p}"


def procedure(rfem, n, threads, mp, sets, tmp):
    """One run of the procedure: {run name: its JSON record}."""
    env = dict(os.environ, OMP_PROC_BIND="close", OMP_PLACES="cores")
    cmd = [rfem, "--threads", str(threads), "run", CASE, "--n", str(n), "--json", "-o", os.path.join(tmp, "r.h5")]
    m, p = mp
    for x in sets + ([f"link.modes={m}"] if m else []) + ([f"link.derivatives={p}"] if p else []):
        cmd += ["--set", x]
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if p.returncode != 0:
        sys.exit(f"reduction_bench: {' '.join(cmd)} failed: {p.stderr.strip()}")
    return {r["name"]: r for r in json.loads(p.stdout)["runs"]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rfem", default=os.path.join(HERE, "..", "build", "apps", "rfem"))
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--modes", default="4,8,16")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--atol", default="1e-10", help="comma-separated simulation.atol values, each optionally /rtol (the first the reference's)")
    ap.add_argument("--set", action="append", default=[], help="case override for every run (key.path=value)")
    a = ap.parse_args()
    ms = [(0, 0)] + [parse_config(x) for x in a.modes.split(",")]
    atols = a.atol.split(",")  # "atol" or "atol/rtol"
    for x in atols:
        for v in x.split("/"):
            float(v)  # (a bad value stops here, before any run)

    def tolerances(x):
        at, _, rt = x.partition("/")
        return [f"simulation.atol={float(at)!r}"] + ([f"simulation.rtol={float(rt)!r}"] if rt else [])
    configs = [(m, at) for at in atols for m in ms]
    print(f"machine: {os.cpu_count()} cores, {os.uname().machine}; n = {a.n}, {a.threads} threads, median of {a.repeat} "
          f"(the configurations interleaved)")
    walls = {c: {"kinematic": [], "force": []} for c in configs}
    last = {}
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(a.repeat):
            for m, at in configs:
                runs = procedure(a.rfem, a.n, a.threads, m, a.set + tolerances(at), tmp)
                for name in ("kinematic", "force"):
                    walls[(m, at)][name].append(runs[name]["wall_time_s"])
                last[(m, at)] = runs
    base = ((0, 0), atols[0])
    ref = statistics.median(walls[base]["kinematic"])
    print(f"{'atol/rtol':>11}{'m:p':>6}{'run':>11}{'wall [s]':>10}{'/kin full':>10}{'steps':>8}{'resid':>8}"
          f"{'d peak u1':>11}{'d peak u2':>11}{'d peak th':>11}")
    for m, at in configs:
        for name in ("kinematic", "force"):
            r, f = last[(m, at)][name], last[base][name]
            d = [abs(r[k] - f[k]) / abs(f[k]) for k in ("peak_u1", "peak_u2", "peak_theta")]
            w = statistics.median(walls[(m, at)][name])
            print(f"{at:>11}{label(m):>6}{name:>11}{w:>10.2f}{w / ref:>10.2f}{r['steps']:>8}{r['residual_evals']:>8}"
                  f"{d[0]:>11.1e}{d[1]:>11.1e}{d[2]:>11.1e}")


if __name__ == "__main__":
    main()
