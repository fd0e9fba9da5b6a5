#!/usr/bin/python3
"""Whole-run benchmark of rfem: the paper's deployment (kinematic and force input) and Kane's
spin-up beam at n = 6, 60, 600, 6000 with 1 and 2 threads.

Prints one table row per run: wall time, IDA steps, residual evaluations, factorisations, wall time
per rfe per residual evaluation, peak memory (max RSS of the process) and, per case and thread
count, the fitted exponent p of wall ∝ n^p between the two largest n.

  /usr/bin/python3 bench/run_bench.py [--rfem build/apps/rfem] [--ns 6,60,600,6000] [--threads 1,2]
Threads are pinned with OMP_PROC_BIND=close OMP_PLACES=cores.
"""
import argparse, json, math, os, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = {
    "deployment": os.path.join(HERE, "..", "cases", "paper_deployment.toml"),
    "spinup": os.path.join(HERE, "..", "cases", "kane_spinup.toml"),
}


def run_measured(rfem, case, n, threads, tmp):
    """Runs rfem and returns (json, max RSS in MB) using wait4 on the child."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads), OMP_PROC_BIND="close", OMP_PLACES="cores")
    out = os.path.join(tmp, f"b{n}_{threads}.h5")
    cmd = [rfem, "run", case, "--n", str(n), "--json", "-o", out]
    with tempfile.TemporaryFile() as so, tempfile.TemporaryFile() as se:
        p = subprocess.Popen(cmd, stdout=so, stderr=se, env=env)
        _, status, usage = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
        so.seek(0)
        se.seek(0)
        if p.returncode != 0:
            sys.exit(f"run_bench: {' '.join(cmd)} failed: {se.read().decode().strip()}")
        os.remove(out)
        return json.loads(so.read()), usage.ru_maxrss / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rfem", default=os.path.join(HERE, "..", "build", "apps", "rfem"))
    ap.add_argument("--ns", default="6,60,600,6000")
    ap.add_argument("--threads", default="1,2")
    ap.add_argument("--cases", default="deployment,spinup")
    a = ap.parse_args()
    ns = [int(x) for x in a.ns.split(",")]
    ths = [int(x) for x in a.threads.split(",")]
    print(f"machine: {os.cpu_count()} cores, {os.uname().machine}, {os.uname().release}")
    hdr = f"{'case':<11}{'run':<10}{'n':>6}{'thr':>4}{'wall [s]':>10}{'steps':>8}{'resid':>8}{'fact':>6}" \
          f"{'us/rfe/res':>11}{'RSS [MB]':>9}"
    print(hdr)
    fits = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in a.cases.split(","):
            for th in ths:
                walls = {}
                for n in ns:
                    js, rss = run_measured(a.rfem, CASES[case], n, th, tmp)
                    total = 0.0
                    for r in js["runs"]:
                        per = r["wall_time_s"] / max(1, r["residual_evals"]) / n * 1e6
                        print(f"{case:<11}{r['name']:<10}{n:>6}{th:>4}{r['wall_time_s']:>10.3f}{r['steps']:>8}"
                              f"{r['residual_evals']:>8}{r['factorizations']:>6}{per:>11.3f}{rss:>9.1f}")
                        total += r["wall_time_s"]
                    walls[n] = total
                    sys.stdout.flush()
                big = sorted(walls)[-2:]
                if len(big) == 2 and walls[big[0]] > 0:
                    p = math.log(walls[big[1]] / walls[big[0]]) / math.log(big[1] / big[0])
                    fits.append(f"{case}, {th} thread(s): wall ∝ n^{p:.2f} between n = {big[0]} and {big[1]}")
    for f in fits:
        print(f)


if __name__ == "__main__":
    main()
