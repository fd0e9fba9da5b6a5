#!/usr/bin/python3
"""Two threads on a shared machine: the paper's procedure (kinematic and force runs) with
`--threads 1`, the default (the governor's adaptive team) and `--threads 2`, each with 0, 1 and 2
foreign CPU-bound processes at normal priority (a user's compile, another run, a shared cluster
node), medians of --repeat interleaved rounds; beside them, on the idle machine, the machine's
ceiling 2·T1/T_pair (two one-thread runs at once: 2.0 when they run as fast as one alone).

    /usr/bin/python3 bench/load_bench.py [--rfem build/apps/rfem] [--n 1000] [--t-end 6] [--repeat 3]
        [--loads 0,1,2] [--before OTHER_RFEM]

--before runs a second binary (an older build) in the same rounds: each row then shows both.
Prints the table of docs/performance.md, "Under load"; results are checked to be the same bits for
every team and load (the runs' peaks and step counts).
"""
import argparse, json, os, subprocess, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
CASE = os.path.join(HERE, "..", "cases", "paper_deployment.toml")
BURN = "while True: pass"


def run(rfem, threads, n, t_end, tmp):
    out = os.path.join(tmp, "load.h5")
    cmd = [rfem] + ([] if threads == "default" else ["--threads", threads]) + [
        "run", CASE, "--n", str(n), "--set", f"simulation.t_end={t_end}", "--json", "-q", "-o", out]
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"load_bench: {' '.join(cmd)} failed: {p.stderr.strip()}")
    os.remove(out)
    return {r["name"]: r for r in json.loads(p.stdout)["runs"]}


def pair(rfem, n, t_end, tmp):
    procs = []
    for k in range(2):
        out = os.path.join(tmp, f"pair{k}.h5")
        cmd = [rfem, "--threads", "1", "run", CASE, "--n", str(n), "--set", f"simulation.t_end={t_end}", "--json", "-q", "-o", out]
        procs.append((subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True), out))
    res = []
    for p, out in procs:
        so, se = p.communicate()
        if p.returncode != 0:
            sys.exit(f"load_bench: a paired run failed: {se.strip()}")
        os.remove(out)
        res.append({r["name"]: r for r in json.loads(so)["runs"]})
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rfem", default=os.path.join(HERE, "..", "build", "apps", "rfem"))
    ap.add_argument("--before", help="an older rfem binary, run in the same rounds")
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--t-end", type=float, default=6.0)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--loads", default="0,1,2")
    a = ap.parse_args()
    binaries = [("now", a.rfem)] + ([("before", a.before)] if a.before else [])
    med = lambda x: sorted(x)[len(x) // 2]
    print(f"machine: {os.cpu_count()} cores, {os.uname().machine}; paper's procedure, n = {a.n}, t_end = {a.t_end} s; "
          f"medians of {a.repeat} interleaved rounds; foreign load: `python3 -c '{BURN}'` at normal priority")
    print(f"{'load':<6}{'build':<8}{'run':<11}{'1 thread':>10}{'default':>10}{'2 threads':>11}{'default/1':>11}{'2 thr/1':>9}")
    signature = None
    with tempfile.TemporaryDirectory() as tmp:
        for load in [int(x) for x in a.loads.split(",")]:
            burners = [subprocess.Popen([sys.executable, "-c", BURN]) for _ in range(load)]
            try:
                time.sleep(0.5)
                walls = {}  # (build, threads) -> list of {run: wall}
                for _ in range(a.repeat):
                    for build, rfem in binaries:
                        for threads in ("1", "default", "2"):
                            runs = run(rfem, threads, a.n, a.t_end, tmp)
                            walls.setdefault((build, threads), []).append({k: r["wall_time_s"] for k, r in runs.items()})
                            sig = {k: (r["steps"], r["peak_u1"], r["peak_u2"], r["peak_theta"]) for k, r in runs.items()}
                            if signature is None:
                                signature = sig
                            elif sig != signature:
                                sys.exit(f"load_bench: {build} --threads {threads} with {load} foreign: results differ: {sig} vs {signature}")
                for build, _ in binaries:
                    for name in ("kinematic", "force"):
                        w = {t: med([x[name] for x in walls[(build, t)]]) for t in ("1", "default", "2")}
                        print(f"{load:<6}{build:<8}{name:<11}{w['1']:>9.2f}s{w['default']:>9.2f}s{w['2']:>10.2f}s"
                              f"{w['default'] / w['1']:>10.2f}×{w['2'] / w['1']:>8.2f}×", flush=True)
            finally:
                for b in burners:
                    b.kill()
                    b.wait()
            if load == 0:  # the ceiling on the idle machine, in rounds of its own
                t1 = [run(a.rfem, "1", a.n, a.t_end, tmp) for _ in range(a.repeat)]
                tp = [r for _ in range(a.repeat) for r in pair(a.rfem, a.n, a.t_end, tmp)]
                for name in ("kinematic", "force"):
                    w1 = med([x[name]["wall_time_s"] for x in t1])
                    wp = med([x[name]["wall_time_s"] for x in tp])
                    print(f"      ceiling  {name:<11} one run alone {w1:.2f} s, two at once {wp:.2f} s each: 2·T1/T_pair = "
                          f"{2 * w1 / wp:.2f}×", flush=True)
    print("results: the same steps and peaks for every build, team and load")


if __name__ == "__main__":
    main()
