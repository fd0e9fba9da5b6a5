#!/usr/bin/env bash
# rfem refine with dynamic quantities from the same runs: the spin-up peak tip deflection converges
# with observed order ≈ 2 over n = 6, 12, 24 (second-order RFEM) with the integration error far
# below the last change; the out-of-plane deflection of this planar motion is round-off, and refine
# says so (a warning, no Richardson value); every run and the tables land in one HDF5 file, and
# rfem plot draws them. A refinement interrupted by SIGINT exits 130 and keeps the rows done.
set -euo pipefail
source "$(dirname "$0")/cli_test_env.sh"
"$rfem" refine "$src/cases/kane_spinup.toml" --n 6,12,24 --quantity peak:u1,peak:u2 --set simulation.t_end=8 -q \
  -o ref.h5 --json > ref.json 2> ref.err
/usr/bin/python3 - <<'PY'
import json, sys, h5py
js = json.load(open("ref.json"))
u1, u2 = js["quantities"]
order, rich = u1["rows"][-1]["order"], u1["rows"][-1]["richardson"]
last_change = abs(u1["rows"][-1]["change"])
f = h5py.File("ref.h5", "r")
groups = sorted(k for k in f.keys() if k.startswith("n"))
checks = {
    "order 2 ± 0.3": 1.7 < order < 2.3,
    "Richardson given": rich is not None,
    "integration error ≪ last change": u1["integration_error"] < 1e-3 * last_change,
    "no warning for u1": not u1["warnings"],
    "u2 flagged": bool(u2["warnings"]) and u2["rows"][-1]["richardson"] is None,
    "runs in the file": groups == ["n12", "n24", "n6"] and "check_n24" in f,
    "table in the file": list(f["refine/n"][:]) == [6, 12, 24] and f["refine/q1"].attrs["quantity"] == "peak:u2",
    "status a string": f["n24/run"].attrs["status"] == "completed",
    "file describes its run": "--quantity" in f.attrs["command_line"] and "case_effective" in f.attrs,
}
for k, v in checks.items():
    print(("ok  " if v else "FAIL"), k)
sys.exit(0 if all(checks.values()) else 1)
PY
grep -q "rfem: warning: peak:u2:" ref.err || { echo "FAIL: no warning on stderr"; exit 1; }
rfem_plot ref.h5 -o figs >/dev/null
test -s figs/refine_convergence.png && test -s figs/refine_convergence_q1.png || { echo "FAIL: figures"; exit 1; }
# Interrupted: exit 130, the rows done so far in the file and on stdout.
"$rfem" refine "$src/cases/paper_deployment.toml" --n 6,8,4000 --quantity force/peak:u1 -q -o part.h5 > part.txt &
pid=$!
for i in $(seq 1 3000); do  # until n = 4000 starts (a sanitizer build needs minutes for n = 6, 8)
  /usr/bin/python3 -c "import h5py,sys; f=h5py.File('part.h5','r',swmr=True); sys.exit(0 if 'n4000' in f else 1)" 2>/dev/null && break
  sleep 0.1
done
sleep 0.5
kill -INT "$pid"
set +e
wait "$pid"
code=$?
set -e
[ "$code" = 130 ] || { echo "FAIL: exit $code on SIGINT (want 130)"; exit 1; }
/usr/bin/python3 - <<'PY'
import sys, h5py
f = h5py.File("part.h5", "r")
ok = list(f["refine/n"][:]) == [6, 8] and f["refine"].attrs["status"].startswith("interrupted")
print(("ok  " if ok else "FAIL"), "partial table kept:", list(f["refine/n"][:]), f["refine"].attrs["status"])
sys.exit(0 if ok else 1)
PY
grep -q "^     8 " part.txt || { echo "FAIL: partial table not printed"; exit 1; }
rfem_plot part.h5 -o figs2 >/dev/null
# A target (docs/accuracy.md): a bad one is one line, exit 2, no file; one that is not met up to
# --max-n says so in the file too (attributes accuracy, met, shortfall) and exits 3.
for bad in 0 nan 1 -1e-3; do
  set +e; err=$("$rfem" refine "$src/cases/kane_beam.toml" --quantity mode:1 --accuracy "$bad" -o bad.h5 2>&1 >/dev/null); code=$?; set -e
  [ "$code" = 2 ] && [ "$(printf '%s\n' "$err" | wc -l)" = 1 ] && [ ! -e bad.h5 ] || { echo "FAIL --accuracy $bad: exit $code: $err"; exit 1; }
done
set +e; "$rfem" refine "$src/cases/kane_beam.toml" --quantity mode:1 --accuracy 1e-8 --max-n 32 -o short.h5 -q >/dev/null; code=$?; set -e
[ "$code" = 3 ] || { echo "FAIL: a target not met exits $code (want 3)"; exit 1; }
/usr/bin/python3 - <<'PY'
import sys, h5py
g = h5py.File("short.h5", "r")["refine"]
ok = g.attrs["accuracy"] == 1e-8 and g.attrs["met"] == 0 and "n ≈" in str(g.attrs["shortfall"]) and g.attrs["asymptotic"] == 1
print(("ok  " if ok else "FAIL"), "a target not met is in the file:", dict(g.attrs))
sys.exit(0 if ok else 1)
PY
# A target on the commands that report values (studies/accuracy.hpp): rfem run, modes and static
# choose n (and, for a run, the tolerances), report each value with its bar (stdout, --json, the
# file's dataset accuracy) and exit 0 when every bar meets it; bad targets are one line, exit 2.
"$rfem" --threads 1 run "$src/cases/kane_spinup.toml" --accuracy 1e-3 -o acc.h5 --json > acc.json 2>/dev/null
"$rfem" modes "$src/cases/kane_beam.toml" --accuracy 1e-4 --count 3 -o accm.h5 --json > accm.json
"$rfem" static "$src/cases/kane_beam.toml" --accuracy tip:uz=1e-6 --json > accs.json
"$rfem" linearize "$src/cases/two_link_arm.toml" --accuracy 1e-3 -o accl.h5 --json > accl.json
/usr/bin/python3 - <<'PY'
import json, math, sys, h5py
run, modes, static, lin = (json.load(open(f)) for f in ("acc.json", "accm.json", "accs.json", "accl.json"))
a = run["accuracy"]
u1 = next(e for e in a["estimates"] if e["quantity"] == "peak:run/u1")
f = h5py.File("acc.h5", "r")
d = f["accuracy"]
row = list(d.attrs["quantities"]).index("peak:run/u1")
m = modes["accuracy"]
checks = {
    "run: met, n chosen, tolerances chosen": a["met"] and run["n"] == a["n"] and a["rtol"] <= 1e-6,
    "run: the reference 0.5738494557 in the bar": abs(u1["value"] - 0.5738494557) <= u1["error"],
    "run: the file's series has the bar's value, at the chosen tolerances":
        abs(abs(f["run/tip_deflection"][:, 0]).max() - u1["value"]) <= 1e-12 * u1["value"] and f["run"].attrs["rtol"] == a["rtol"],
    "file: the bar beside the value": d[row, 0] == u1["value"] and d[row, 1] == u1["error"] and d.attrs["met"] == 1,
    "modes: three frequencies with bars, met": m["met"] and len(m["estimates"]) == 3 and all(e["error"] > 0 for e in m["estimates"]),
    "modes: the file has them": h5py.File("accm.h5", "r")["accuracy"].shape == (3, 8),
    "linearize: six frequencies with bars, the model's own": lin["accuracy"]["met"] and
        all(abs(e["value"] - f) <= 1e-9 * f for e, f in zip(lin["accuracy"]["estimates"], lin["frequencies_hz"])) and
        h5py.File("accl.h5", "r")["accuracy"].shape == (6, 8),
    "static: the absolute target on tip:uz": static["accuracy"]["met"] and
        next(e for e in static["accuracy"]["estimates"] if e["quantity"] == "tip:uz")["error"] <= 1e-6,
}
for k, ok in checks.items():
    print(("ok  " if ok else "FAIL"), k)
sys.exit(0 if all(checks.values()) else 1)
PY
for bad in "0" "-1e-3" "nan" "1e-12" "peak:nope=1e-3" "peak:u1=0" "abc"; do
  set +e; err=$("$rfem" run "$src/cases/kane_spinup.toml" --accuracy "$bad" -o badacc.h5 2>&1 >/dev/null); code=$?; set -e
  [ "$code" = 2 ] && [ "$(printf '%s\n' "$err" | wc -l)" = 1 ] && [ ! -e badacc.h5 ] || { echo "FAIL run --accuracy $bad: exit $code: $err"; exit 1; }
done
set +e; err=$("$rfem" modes "$src/cases/kane_beam.toml" --accuracy 1e-3 --n 16 2>&1 >/dev/null); code=$?; set -e
[ "$code" = 2 ] && [ "$(printf '%s\n' "$err" | wc -l)" = 1 ] || { echo "FAIL --n with --accuracy: exit $code: $err"; exit 1; }
set +e; "$rfem" modes "$src/cases/kane_beam.toml" --accuracy 1e-8 --max-n 32 -q > /dev/null; code=$?; set -e
[ "$code" = 3 ] || { echo "FAIL: modes with a target not met exits $code (want 3)"; exit 1; }
# A wall-time limit: bad values and a limit without a target are one line, exit 2; a limit no level
# after the first fits in stops the ladder, and the target is not met (exit 3, the reason printed).
for bad in "0" "-1" "nan" "abc"; do
  set +e; err=$("$rfem" modes "$src/cases/kane_beam.toml" --accuracy 1e-4 --max-time "$bad" 2>&1 >/dev/null); code=$?; set -e
  [ "$code" = 2 ] && [ "$(printf '%s\n' "$err" | wc -l)" = 1 ] || { echo "FAIL --max-time $bad: exit $code: $err"; exit 1; }
done
set +e; err=$("$rfem" modes "$src/cases/kane_beam.toml" --max-time 10 2>&1 >/dev/null); code=$?; set -e
[ "$code" = 2 ] && [ "$(printf '%s\n' "$err" | wc -l)" = 1 ] || { echo "FAIL --max-time without a target: exit $code: $err"; exit 1; }
set +e; out=$("$rfem" modes "$src/cases/kane_beam.toml" --accuracy 1e-4 --max-time 1e-6 2>/dev/null); code=$?; set -e
[ "$code" = 3 ] && printf '%s\n' "$out" | grep -q "past --max-time" || { echo "FAIL: --max-time 1e-6 exits $code: $out"; exit 1; }
echo "refine: all passed"
