#!/usr/bin/env bash
# What a new user trips over, each as the command that showed it: a results file that
# describes its own run; command-line errors as one line with exit 2 (and global options after the
# command); a directory given as a case; plausibility warnings; degrees; a capped --count; plot
# errors that blame the right path; a run that can be watched (HDF5 SWMR) with strings, integers
# and per-column names and units as such; the rigid run's energy balance closing; the torque_from_run round trip; a large run's estimate.
set -uo pipefail
source "$(dirname "$0")/cli_test_env.sh"
fail=0
ok() { echo "ok   $*"; }
bad() { echo "FAIL $*"; fail=1; }

# 1. The file describes its own run: the effective case after --set, the overrides, the command line.
"$rfem" run "$src/cases/kane_spinup.toml" --set joints.0.input.Omega=10 --set simulation.t_end=0.5 -q -o om10.h5
/usr/bin/python3 - <<'PY' && ok "results file describes its run" || bad "results file attributes"
import sys, h5py
f = h5py.File("om10.h5", "r")
a = f.attrs
checks = [
    "Omega = 10" in a["case_effective"] and "t_end = 0.5" in a["case_effective"],
    "Omega = 6.0" in a["case_text"],
    a["overrides"] == "joints.0.input.Omega=10\nsimulation.t_end=0.5",
    "--set joints.0.input.Omega=10" in a["command_line"],
    a["rfem_version"] != "" and "Release" in a["build"] or "Debug" in a["build"] or "RelWithDebInfo" in a["build"],
    isinstance(a["n"], (int,)) or a["n"].dtype.kind == "i",
]
print(checks)
sys.exit(0 if all(checks) else 1)
PY

# 2. Command-line errors: one line on stderr, exit 2.
expect_2() {  # description, args...
  local what=$1; shift
  "$rfem" "$@" > out.txt 2> err.txt
  local code=$?
  if [ "$code" = 2 ] && [ "$(wc -l < err.txt)" = 1 ] && grep -q "^rfem: error: " err.txt; then ok "$what: $(cat err.txt)"
  else bad "$what: exit $code, stderr: $(cat err.txt)"; fi
}
expect_2 "--threads 0" --threads 0 run "$src/cases/kane_spinup.toml"
expect_2 "--n 0" run "$src/cases/kane_spinup.toml" --n 0
expect_2 "--n -5" run "$src/cases/kane_spinup.toml" --n -5
expect_2 "--n abc" run "$src/cases/kane_spinup.toml" --n abc
expect_2 "--n 1e3" run "$src/cases/kane_spinup.toml" --n 1e3
expect_2 "--count 0" modes "$src/cases/kane_beam.toml" --count 0
expect_2 "unknown command" frob "$src/cases/kane_beam.toml"
expect_2 "a directory as the case" run "$src/cases"
expect_2 "refine with repeated n" refine "$src/cases/kane_spinup.toml" --n 10,10,20 --quantity peak:u1
expect_2 "refine beyond t_end" refine "$src/cases/kane_spinup.toml" --n 10,20,40 --quantity u1@30
expect_2 "refine without a quantity" refine "$src/cases/kane_spinup.toml" --n 10,20
expect_2 "modes --free of an unknown joint" modes "$src/cases/kane_spinup.toml" --free elbow
expect_2 "modes --free base without a free base" modes "$src/cases/kane_spinup.toml" --free base
expect_2 "modes --free of a joint under a static torque" modes "$src/cases/kane_spinup.toml" --free hub \
  --set joints.0.alpha=1.5707963267948966 --set gravity.g=9.81
grep -q "directory" <("$rfem" run "$src/cases" 2>&1) && ok "directory named as such" || bad "directory message"
"$rfem" run "$src/cases/kane_spinup.toml" --set simulation.t_end=0.1 -q -o t1.h5 --threads 1 \
  && ok "global option after the command" || bad "--threads after the command"

# 3. Plausibility warnings name the key; degrees are accepted; --count is capped with a note.
"$rfem" static "$src/cases/kane_beam.toml" --set materials.kane.G=1e11 > /dev/null 2> w.txt
grep -q "rfem: warning: .*materials.kane.G: G > E/2" w.txt && ok "G > E/2 warned" || bad "G > E/2: $(cat w.txt)"
"$rfem" static "$src/cases/kane_beam.toml" --set sections.kane.Iy=1 > /dev/null 2> w.txt
grep -q "sections.kane.Iy: a second moment of 10 A^2 or more" w.txt && ok "I > A² warned" || bad "I > A²: $(cat w.txt)"
"$rfem" static "$src/cases/kane_beam.toml" --set materials.kane.E=70 --set materials.kane.G=26 > /dev/null 2> w.txt
[ $? = 2 ] && grep -q "materials.kane.E: E = 70 Pa is very small" w.txt && ok "E in GPa refused" || bad "E: $(cat w.txt)"
"$rfem" run "$src/cases/paper_deployment.toml" --set 'joints.1.alpha=90' --set simulation.t_end=0.1 -q -o d.h5 2> w.txt
grep -q 'joints.1.alpha: |90| rad is more than a turn' w.txt && ok "radians that look like degrees warned" || bad "degrees: $(cat w.txt)"
"$rfem" run "$src/cases/paper_deployment.toml" --set 'joints.1.alpha="90 deg"' --set simulation.t_end=0.1 -q -o deg.h5 2> w.txt
"$rfem" run "$src/cases/paper_deployment.toml" --set simulation.t_end=0.1 -q -o rad.h5
/usr/bin/python3 -c "
import h5py, numpy as np, sys
a, b = h5py.File('deg.h5')['kinematic/joint_tau'][:], h5py.File('rad.h5')['kinematic/joint_tau'][:]
sys.exit(0 if np.abs(a - b).max() <= 1e-9 * np.abs(b).max() else 1)" && ! grep -q alpha w.txt \
  && ok "\"90 deg\" = pi/2 rad, silently" || bad "deg string: $(cat w.txt)"
"$rfem" modes "$src/cases/kane_beam.toml" --n 2 --count 100 > /dev/null 2> w.txt
grep -q "capped at 6n = 12" w.txt && ok "--count capped with a note" || bad "count cap: $(cat w.txt)"

# 4. plot blames the right path.
"$rfem" plot om10.h5 -o /proc/nope > /dev/null 2> err.txt; code=$?
[ $code = 2 ] && grep -q "/proc/nope" err.txt && ok "plot blames the output directory" || bad "plot -o: $code $(cat err.txt)"

# 5. A run can be watched: SWMR readers see the rows grow and the live status; strings are str,
#    integers int, columns and units arrays.
# (One kinematic run of 1500 rfes to watch; the paper procedure's three runs at n = 6 for the rest.)
"$rfem" run "$src/cases/paper_deployment.toml" --n 1500 -q -o live.h5 --set simulation.t_end=2 \
  --set simulation.procedure=single &
pid=$!
/usr/bin/python3 - <<'PY' && ok "watched while running (SWMR)" || bad "SWMR read while running"
import sys, time, h5py
for _ in range(3000):
    try:
        f = h5py.File("live.h5", "r", swmr=True)
        if "run" in f:
            break
        f.close()
    except OSError:
        pass
    time.sleep(0.1)
else:
    sys.exit("never saw the run")
g = f["run"]
# Poll until the rows grow while the status says running, not for a fixed window: under a
# sanitizer on a busy machine the first step of a 1500-rfe run can outlast any fixed window.
def now():
    g["time"].refresh()
    g["status_now"].refresh()
    return g["time"].shape[0], g["status_now"][()].decode().rstrip("\0")
first = now()
seen = [first]
deadline = time.time() + 600
while time.time() < deadline and seen[-1][1] == "running" and seen[-1][0] <= first[0]:
    time.sleep(0.2)
    seen.append(now())
print("rows, status seen:", first, "→", seen[-1])
sys.exit(0 if first[1] == "running" and seen[-1][0] > first[0] else 1)
PY
wait $pid
"$rfem" run "$src/cases/paper_deployment.toml" -q -o paper.h5 --set simulation.t_end=2
/usr/bin/python3 - <<'PY' && ok "strings, integers, column names and units" || bad "HDF5 conventions"
import sys, h5py, numpy as np
g = h5py.File("paper.h5", "r")["force"]
live = h5py.File("live.h5", "r")["run"]
checks = [
    g.attrs["status"] == "completed" and live.attrs["status"] == "completed",
    isinstance(g.attrs["steps"], (np.integer, int)),
    list(g.attrs["joint_types"]) == ["revolute"] * 3 and list(g.attrs["joint_units"]) == ["rad"] * 3,
    list(g["tip_deflection"].attrs["columns"]) == ["u1", "u2", "theta"],
    list(g["tip_deflection"].attrs["units"]) == ["m", "m", "rad"],
    g["rfe_centre"].shape == (6, 3) and live["rfe_centre"].shape == (1500, 3),
    g["tip_position"].shape[1] == 3 and abs(np.linalg.norm(g["tip_position"][0]) - 8.0) < 2.5,
]
print(checks)
sys.exit(0 if all(checks) else 1)
PY

# 6. The rigid run (no integration) closes its energy balance to round-off (Simpson's input work).
/usr/bin/python3 - <<'PY' && ok "rigid run's balance closes" || bad "rigid balance"
import sys, h5py, numpy as np
e = h5py.File("paper.h5", "r")["rigid/energy"][:]
drift = np.abs(e[:, 5] - e[0, 5]).max()
print("rigid balance drift", drift, "J on", np.abs(e[:, 3]).max())
sys.exit(0 if drift < 1e-8 * np.abs(e[:, 3]).max() else 1)
PY

# 7. torque_from_run closes the round trip: the spin-up's required torque (kinematic input, n = 20)
#    applied as force input reproduces the hub angle. The torque is a cubic spline through the 0.05 s
#    outputs (error O(h^4), ~1e-9 of the torque) and both runs integrate at rtol 1e-8, so the angle,
#    75 rad at the end, must agree to 2e-6 rad (3e-8 relative); a linear interpolant missed by 1e-4 rad.
#    A source that ends before t_end is refused; one that did not complete is used with a warning.
"$rfem" run "$src/cases/kane_spinup.toml" --n 20 -q -o rt_kin.h5
sed -e 's|input = { kind = "spinup".*|input = { kind = "torque_from_run", file = "rt_kin.h5", run = "run", joint = 1 }|' \
  "$src/cases/kane_spinup.toml" > rt_force.toml
"$rfem" run rt_force.toml --n 20 -q -o rt_force.h5
/usr/bin/python3 - <<'PY' && ok "torque_from_run round trip" || bad "torque_from_run round trip"
import sys, h5py, numpy as np
a, b = h5py.File("rt_kin.h5", "r")["run"], h5py.File("rt_force.h5", "r")["run"]
dq = np.abs(a["joint_q"][:, 0] - b["joint_q"][:, 0]).max()
du = np.abs(a["tip_deflection"][:, 0] - b["tip_deflection"][:, 0]).max()
print("round trip: hub angle", dq, "rad of", a["joint_q"][-1, 0], "; tip u1", du, "m")
sys.exit(0 if b.attrs["status"] == "completed" and a["time"].shape == b["time"].shape and dq < 2e-6 else 1)
PY
"$rfem" run rt_force.toml --n 20 -q --set simulation.t_end=25 -o rt_past.h5 2> err.txt
code=$?
if [ $code = 2 ] && grep -q "ends at t = 20 s.*before simulation.t_end = 25 s" err.txt; then ok "source shorter than t_end refused"
else bad "source shorter than t_end: exit $code $(cat err.txt)"; fi
cp rt_kin.h5 rt_int.h5
/usr/bin/python3 -c "import h5py; h5py.File('rt_int.h5', 'r+')['run'].attrs['status'] = 'interrupted (signal 2)'"
sed -e 's|rt_kin.h5|rt_int.h5|' rt_force.toml > rt_int.toml
"$rfem" run rt_int.toml --n 20 -q --set simulation.t_end=1 -o rt_int_out.h5 2> err.txt
if [ $? = 0 ] && grep -q "warning: .*did not complete (interrupted (signal 2))" err.txt; then ok "incomplete source warned"
else bad "incomplete source: $(cat err.txt)"; fi

# 8. A large run says what it will cost before it starts (memory from the measured 1.92 KiB per rfe:
#    10 000 rfes are 22 MB + 20 MB; the timed step cost is positive).
"$rfem" run "$src/cases/kane_spinup.toml" --n 10000 --set simulation.t_end=0.05 -o big.h5 > out.txt 2> err.txt
if [ $? = 0 ] && grep -Eq "^rfem: note: n = 10000 rfes: about 4[0-9] MB of memory; one residual evaluation [0-9.e-]+ ms, .*s per step" err.txt
then ok "large run estimated: $(cat err.txt)"; else bad "large-run note: $(cat err.txt)"; fi

# 9. An error with nowhere to write it (stderr full) still exits 2, not an abort.
"$rfem" run missing.toml 2> /dev/full
code=$?
[ $code = 2 ] && ok "error with a full stderr: exit 2" || bad "error with a full stderr: exit $code"

[ $fail = 0 ] && echo "new user: all passed" || echo "new user: failures above"
exit $fail
