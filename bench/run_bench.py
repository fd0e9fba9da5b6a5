#!/usr/bin/python3
"""Whole-run benchmark of rfem at its default settings: the paper's deployment (kinematic and force
input) and Kane's spin-up beam over a series of n, with `--threads 1`, `--threads 2` and without
--threads ("auto": each run times one thread against two and keeps the faster).

Prints one table row per run: median wall time over --repeat runs, steps, residual evaluations,
factorisations, wall time per rfe per step and per residual evaluation, peak memory (max RSS of the
process, its growth per rfe between the two largest n) and, per case and thread mode, the fitted
exponent p of wall ∝ n^p between the two largest n.

  /usr/bin/python3 bench/run_bench.py [--ns 600,2000,10000] [--threads 1,2,auto] [--repeat 3]
      [--cases deployment,spinup] [--set key=value …]
Threads are pinned with OMP_PROC_BIND=close OMP_PLACES=cores.

--speedup: instead of the table, the second core's worth per case and n, with the machine's ceiling
beside it (a busy or throttled machine cannot hide a regression): rounds of one-thread run,
two-thread run and two one-thread runs at once, interleaved; per run of the procedure the medians,
the speed-up T1/T2 and the ceiling 2·T1/T_pair (2.0 when two processes run as fast as one alone).
  /usr/bin/python3 bench/run_bench.py --speedup --ns 1000 --cases deployment --repeat 3
"""
import argparse, json, math, os, subprocess, sys, tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = {
    "deployment": os.path.join(HERE, "..", "cases", "paper_deployment.toml"),
    "spinup": os.path.join(HERE, "..", "cases", "kane_spinup.toml"),
}


def run_measured(rfem, case, n, threads, tmp, sets):
    """Runs rfem and returns (json, max RSS in MB) using wait4 on the child."""
    env = dict(os.environ, OMP_PROC_BIND="close", OMP_PLACES="cores")
    out = os.path.join(tmp, f"b{n}_{threads}.h5")
    cmd = [rfem] + ([] if threads == "auto" else ["--threads", threads]) + ["run", case, "--n", str(n), "--json", "-o", out]
    for x in sets:
        cmd += ["--set", x]
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


def run_pair(rfem, case, n, tmp, sets):
    """Two one-thread runs started together; returns both runs' JSON."""
    env = dict(os.environ, OMP_PROC_BIND="close", OMP_PLACES="cores")
    procs = []
    for k in range(2):
        out = os.path.join(tmp, f"pair{k}_{n}.h5")
        cmd = [rfem, "--threads", "1", "run", case, "--n", str(n), "--json", "-o", out]
        for x in sets:
            cmd += ["--set", x]
        procs.append((subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True), out, cmd))
    res = []
    for p, out, cmd in procs:
        so, se = p.communicate()
        if p.returncode != 0:
            sys.exit(f"run_bench: {' '.join(cmd)} failed: {se.strip()}")
        os.remove(out)
        res.append(json.loads(so))
    return res


def speedup(a, ns):
    """--speedup: T1, T2 and the ceiling measured beside them, medians of interleaved rounds."""
    print(f"machine: {os.cpu_count()} cores, {os.uname().machine}, {os.uname().release}; "
          f"median of {a.repeat} interleaved rounds (1 thread, 2 threads, two 1-thread runs at once)")
    print(f"{'case':<11}{'run':<10}{'n':>6}{'1 thr [s]':>11}{'2 thr [s]':>11}{'speed-up':>10}{'pair [s]':>10}{'ceiling':>9}")
    med = lambda x: sorted(x)[len(x) // 2]
    with tempfile.TemporaryDirectory() as tmp:
        for case in a.cases.split(","):
            for n in ns:
                t1, t2, tp = [], [], []
                for _ in range(a.repeat):
                    t1.append(run_measured(a.rfem, CASES[case], n, "1", tmp, a.set)[0])
                    t2.append(run_measured(a.rfem, CASES[case], n, "2", tmp, a.set)[0])
                    tp.extend(run_pair(a.rfem, CASES[case], n, tmp, a.set))
                names = [r["name"] for r in t1[0]["runs"]] + ["total"]
                for i, name in enumerate(names):
                    def wall(js):
                        runs = js["runs"]
                        return sum(r["wall_time_s"] for r in runs) if name == "total" else runs[i]["wall_time_s"]
                    w1, w2, wp = med([wall(j) for j in t1]), med([wall(j) for j in t2]), med([wall(j) for j in tp])
                    if w1 < 0.1:
                        continue  # (the rigid run: nothing to measure)
                    print(f"{case:<11}{name:<10}{n:>6}{w1:>11.2f}{w2:>11.2f}{w1 / w2:>9.2f}×{wp:>10.2f}{2 * w1 / wp:>8.2f}×",
                          flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rfem", default=os.path.join(HERE, "..", "build", "apps", "rfem"))
    ap.add_argument("--ns", default="600,2000,10000")
    ap.add_argument("--threads", default="1,2,auto")
    ap.add_argument("--cases", default="deployment,spinup")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--set", action="append", default=[], help="case override for every run (key.path=value)")
    ap.add_argument("--speedup", action="store_true", help="the second core's speed-up beside the machine's ceiling")
    a = ap.parse_args()
    ns = [int(x) for x in a.ns.split(",")]
    if a.speedup:
        speedup(a, ns)
        return
    ths = a.threads.split(",")
    print(f"machine: {os.cpu_count()} cores, {os.uname().machine}, {os.uname().release}; median of {a.repeat}")
    hdr = f"{'case':<11}{'run':<10}{'n':>6}{'thr':>5}{'wall [s]':>10}{'steps':>8}{'resid':>8}{'fact':>6}" \
          f"{'us/rfe/step':>12}{'us/rfe/res':>11}{'RSS [MB]':>9}"
    print(hdr)
    fits = []
    with tempfile.TemporaryDirectory() as tmp:
        for case in a.cases.split(","):
            for th in ths:
                walls, rsss = {}, {}
                for n in ns:
                    reps = [run_measured(a.rfem, CASES[case], n, th, tmp, a.set) for _ in range(a.repeat)]
                    rsss[n] = max(r[1] for r in reps)
                    total = 0.0
                    for i, r in enumerate(reps[0][0]["runs"]):
                        wall = sorted(rep[0]["runs"][i]["wall_time_s"] for rep in reps)[len(reps) // 2]
                        step = wall / max(1, r["steps"]) / n * 1e6
                        per = wall / max(1, r["residual_evals"]) / n * 1e6
                        print(f"{case:<11}{r['name']:<10}{n:>6}{th:>5}{wall:>10.3f}{r['steps']:>8}"
                              f"{r['residual_evals']:>8}{r['factorizations']:>6}{step:>12.3f}{per:>11.3f}{rsss[n]:>9.1f}")
                        total += wall
                    walls[n] = total
                    sys.stdout.flush()
                big = sorted(walls)[-2:]
                if len(big) == 2 and walls[big[0]] > 0:
                    p = math.log(walls[big[1]] / walls[big[0]]) / math.log(big[1] / big[0])
                    kb = (rsss[big[1]] - rsss[big[0]]) * 1024 / (big[1] - big[0])
                    fits.append(f"{case}, threads {th}: wall ∝ n^{p:.2f} between n = {big[0]} and {big[1]}; "
                                f"memory {kb:.2f} KB per rfe")
    for f in fits:
        print(f)


if __name__ == "__main__":
    main()
