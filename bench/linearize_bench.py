#!/usr/bin/python3
"""Cost of a linear model (README, "Linear models"; docs/formulation.md §8, "Sparsity"): rfem.linearize
on the paper's deployment (cases/paper_deployment.toml: 6n states, every joint prescribed) and on the
two-link arm (cases/two_link_arm.toml: two free joints under PD laws, whose rows see every rfe), the
sparse method over --ns and the column-by-column reference (`dense=True`) over --dense-ns. Per
configuration the median over --repeat calls of the wall time of rfem.linearize (the case's model
and static equilibrium included, as a user calls it), the evaluations of the equations, K's nonzeros,
and the time of the six lowest modes (LinearModel.modes: dense up to 16 states, else shift-invert
on the sparse pencil). One thread.

  PYTHONPATH=build/python /usr/bin/python3 bench/linearize_bench.py [--ns 100,1000,10000]
      [--dense-ns 50,100,200] [--repeat 3] [--name linearize]
Writes bench/results/NAME.md and .csv.
"""
import argparse, csv, os, statistics, sys, time

HERE = os.path.dirname(os.path.abspath(__file__))
CASES = {"deployment": "paper_deployment.toml", "arm": "two_link_arm.toml"}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ns", default="100,1000,10000")
    ap.add_argument("--dense-ns", default="50,100,200")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--name", default="linearize")
    a = ap.parse_args()
    import rfem
    rows = []
    configs = [(c, n, False) for c in CASES for n in map(int, a.ns.split(","))]
    configs += [(c, n, True) for c in CASES for n in map(int, a.dense_ns.split(",")) if n]
    print(f"machine: {os.cpu_count()} cores, {os.uname().machine}; one thread, median of {a.repeat}")
    for c, n, dense in configs:
        case = rfem.load(os.path.join(HERE, "..", "cases", CASES[c]))
        walls, mwalls = [], []
        for _ in range(a.repeat):
            t0 = time.perf_counter()
            lin = rfem.linearize(case, n=n, threads=1, dense=dense)
            walls.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            f = lin.modes(6)
            mwalls.append(time.perf_counter() - t0)
        row = {"case": c, "n": n, "states": len(lin.states), "method": "dense" if dense else "sparse",
               "evaluations": lin.evaluations, "K_nonzeros": lin.K.nnz, "linearize_s": statistics.median(walls),
               "modes_s": statistics.median(mwalls), "f1_hz": f[0][0] if f else float("nan")}
        rows.append(row)
        print("{case:10s} n = {n:6d}: {states:6d} states, {method:6s}: {evaluations:6d} evaluations, "
              "{linearize_s:8.3f} s; modes {modes_s:.3f} s (f1 {f1_hz:.6g} Hz)".format(**row), flush=True)
    out = os.path.join(HERE, "results", a.name)
    with open(out + ".csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    with open(out + ".md", "w") as fh:
        fh.write(f"# Linear models: cost (bench/linearize_bench.py; {os.cpu_count()} cores, one thread, "
                 f"median of {a.repeat})\n\n")
        fh.write("| case | n | states | method | evaluations | K nonzeros | rfem.linearize | six lowest modes | f1 [Hz] |\n")
        fh.write("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n")
        for r in rows:
            fh.write("| {case} | {n} | {states} | {method} | {evaluations} | {K_nonzeros} | {linearize_s:.3f} s | "
                     "{modes_s:.3f} s | {f1_hz:.6g} |\n".format(**r))
    print(f"wrote {out}.md, .csv")


if __name__ == "__main__":
    sys.exit(main())
