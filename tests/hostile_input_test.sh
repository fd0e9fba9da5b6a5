#!/usr/bin/env bash
# Nothing lost, nothing false: hostile files and faults end in a one-line error with README's exit
# code (2 bad input, 1 failure, 128+N signals) or in correct results — never a crash, a hang, NaN
# or a false "completed" — and a failed run's file says why. Each check names the defect it guards.
set -uo pipefail
source "$(dirname "$0")/cli_test_env.sh"
fail=0
ok() { echo "ok   $*"; }
bad() { echo "FAIL $*"; fail=1; }
one_line() {  # want-code what, after a command wrote err.txt and returned $code
  if [ "$code" = "$1" ] && [ "$(wc -l < err.txt)" = 1 ] && grep -q "^rfem: error: " err.txt; then ok "$2: $(cut -c1-150 err.txt)"
  else bad "$2: exit $code (want $1), stderr: $(head -c 400 err.txt)"; fi
}
status() {  # file group: prints the run's status attribute and t_reached
  /usr/bin/python3 - "$@" <<'PY'
import sys, h5py
try:
    f = h5py.File(sys.argv[1], "r")
except OSError:
    f = h5py.File(sys.argv[1], "r", libver="latest", swmr=True)
g = f[sys.argv[2]]
print(g.attrs["status"], "|", g.attrs.get("t_reached", "none"), "|", g["time"].shape[0])
PY
}
hub_case() {  # $1: the hub's input table; writes hub.toml
  cat > hub.toml <<EOF
[materials.al]
E = 7.0e10
G = 2.7e10
rho = 2700.0
[sections.s]
A = 4.0e-4
Iy = 2.0e-7
Iz = 2.0e-7
J = 4.0e-7
[link]
n = 4
[[link.segments]]
length = 1.0
material = "al"
section = "s"
[[joints]]
name = "hub"
body = { mass = 1.0, inertia = [0.1, 0.1, 0.1, 0, 0, 0] }
input = $1
[simulation]
t_end = 0.3
output_dt = 0.01
EOF
}

# 1. torque_from_run trusts nothing of its source file: rank-3 series (once heap corruption), 51
#    times against 26 torques (once a torque of 0.02 where the file says 1.0), a NaN sample (once a hang).
/usr/bin/python3 - <<'PY'
import h5py, numpy as np
t = np.linspace(0, 0.5, 51)
with h5py.File("rank3.h5", "w") as f:
    f["run/time"] = t[:, None, None] * np.ones((1, 1, 4)); f["run/joint_tau"] = np.ones((51, 1, 4))
    f["run"].attrs["status"] = "completed"
with h5py.File("rows.h5", "w") as f:
    f["run/time"] = t[:, None]; f["run/joint_tau"] = np.ones((26, 1))
    f["run"].attrs["status"] = "completed"
with h5py.File("nan.h5", "w") as f:
    tau = np.ones((51, 1)); tau[40, 0] = np.nan
    f["run/time"] = t[:, None]; f["run/joint_tau"] = tau
    f["run"].attrs["status"] = "completed"
with h5py.File("good.h5", "w") as f:
    f["run/time"] = t[:, None]; f["run/joint_tau"] = np.ones((51, 1))
    f["run"].attrs["status"] = "completed"
PY
for source in rank3 rows nan; do
  hub_case "{ kind = \"torque_from_run\", file = \"$source.h5\", run = \"run\", joint = 1 }"
  timeout 60 "$rfem" run hub.toml -q -o out.h5 2> err.txt; code=$?
  one_line 2 "torque_from_run from $source.h5"
done
hub_case '{ kind = "torque_from_run", file = "good.h5", run = "run", joint = 1 }'
"$rfem" run hub.toml -q -o good_out.h5 2> err.txt && /usr/bin/python3 -c "
import h5py, numpy as np, sys
tau = h5py.File('good_out.h5')['run/joint_tau'][:, 0]
sys.exit(0 if np.abs(tau - 1.0).max() < 1e-12 else 1)" && ok "torque_from_run of a sound file: torque 1.0 throughout" || bad "torque_from_run: $(cat err.txt)"

# 2. A table behind a byte-order mark keeps its first row (once dropped as a header: torque 0, not 100).
printf '\xef\xbb\xbf0.0, 100\n0.1, 90\n0.3, 70\n' > bom.csv
hub_case '{ kind = "torque_table", file = "bom.csv" }'
"$rfem" run hub.toml -q -o bom.h5 2> err.txt && /usr/bin/python3 -c "
import h5py, sys
tau = h5py.File('bom.h5')['run/joint_tau'][:, 0]
sys.exit(0 if abs(tau[0] - 100) < 1e-12 and abs(tau[5] - 95) < 1e-9 else 1)" && ok "table behind a BOM: torque 100 at t = 0, 95 at 0.05 s" || bad "BOM table: $(cat err.txt)"

# 3. A run that fails at its start records why (once: exit 1 with status "running", no t_reached):
#    a point mass on its joint's axis (no inertia about it; a joint with no mass at all is refused
#    at reading).
cat > massless.toml <<'EOF'
[[joints]]
name = "free"
body = { mass = 1.0 }
input = { kind = "torque", value = 1.0 }
[simulation]
t_end = 0.1
output_dt = 0.01
EOF
"$rfem" run massless.toml -q -o massless.h5 2> err.txt; code=$?
one_line 1 "a joint with nothing to move"
s=$(status massless.h5 run)
[[ $s == "failed: "*" | 0.0 | 0" ]] && ok "its file says: $s" || bad "massless status: $s"

# 4. NaN never completes (once: exit 0, NaN in joint_v, joint_a, energy).
"$rfem" run "$src/cases/two_link_arm.toml" --set joints.0.drive.friction=1e308 --set simulation.t_end=0.3 -q \
  -o nan_run.h5 2> err.txt; code=$?
one_line 1 "a drive friction of 1e308"
s=$(status nan_run.h5 run)
[[ $s == "failed: non-finite values"* ]] && ok "its file says: ${s:0:90}" || bad "NaN run status: $s"
/usr/bin/python3 -c "
import h5py, numpy as np, sys
g = h5py.File('nan_run.h5')['run']
sys.exit(0 if all(np.isfinite(g[k][()]).all() for k in ('joint_q', 'joint_v', 'joint_a', 'energy')) else 1)" \
  && ok "no NaN among the rows it kept" || bad "NaN rows in nan_run.h5"
"$rfem" modes "$src/cases/kane_hub_drive.toml" --set materials.kane.rho=1e308 --count 1 > out.txt 2> err.txt; code=$?
one_line 2 "modes with rho = 1e308 (refused at reading)"
grep -qiE "nan|inf" out.txt && bad "modes printed nan or inf: $(cat out.txt)" || ok "modes printed no nan or inf"

# 5. Bounded work: an output interval of 1e-18 s is refused at once (once: SIGTERM ignored, 5 GB).
timeout 20 "$rfem" run "$src/cases/kane_spinup.toml" --set simulation.output_dt=1e-18 -q -o big.h5 2> err.txt; code=$?
one_line 2 "output_dt = 1e-18"

# 6. Output files: the case itself and a file that is not HDF5 are not overwritten; a second run on
#    the same file is refused while the first writes (once: the first run's groups vanished).
cp "$src/cases/kane_spinup.toml" mine.toml
"$rfem" run mine.toml -q -o mine.toml 2> err.txt; code=$?
one_line 2 "-o naming the case"
cmp -s mine.toml "$src/cases/kane_spinup.toml" && ok "the case is intact" || bad "the case was changed"
echo "notes" > notes.txt
"$rfem" run mine.toml -q -o notes.txt 2> err.txt; code=$?
one_line 2 "-o naming a text file"
"$rfem" --threads 1 run "$src/cases/paper_deployment.toml" --n 40 -q -o shared.h5 2> first.err &
pid=$!
for _ in $(seq 300); do [ -s shared.h5 ] && break; sleep 0.05; done
"$rfem" --threads 1 run "$src/cases/kane_spinup.toml" --set simulation.t_end=0.5 -q -o shared.h5 2> err.txt; code=$?
one_line 2 "a second run on a file the first writes"
wait $pid
s=$(status shared.h5 force)
[[ $s == "completed | 20.0 | 1001" ]] && ok "the first run's file is whole: force $s" || bad "first run: $s ($(cat first.err))"

# A long run writing $1, once it has written two outputs (read live, SWMR); its pid in $pid.
start_long_run() {
  "$rfem" run "$src/cases/paper_deployment.toml" --n 1500 --set simulation.procedure=\"single\" -q -o "$1" 2>/dev/null &
  pid=$!
  for _ in $(seq 600); do
    /usr/bin/python3 -c "
import h5py, sys
d = h5py.File('$1', 'r', libver='latest', swmr=True)['run/time']; d.refresh(); sys.exit(0 if d.shape[0] >= 2 else 1)" 2>/dev/null && break
    sleep 0.1
  done
}

# 7. SIGHUP (a closed terminal) stops a run like SIGTERM, its file closed (once: left flagged open).
start_long_run hup.h5
kill -HUP $pid; wait $pid; code=$?
[ $code = 129 ] && ok "SIGHUP: exit 129" || bad "SIGHUP: exit $code"
/usr/bin/python3 -c "import h5py; print(h5py.File('hup.h5', 'r')['run'].attrs['status'])" 2>&1 | grep -q "interrupted (signal 1)" \
  && ok "after SIGHUP the file opens plainly: interrupted (signal 1)" || bad "hup.h5 does not open plainly"

# 8. SIGKILL leaves the file flagged open for SWMR: it opens with swmr=True (README), and rfem plot
#    reads it.
start_long_run killed.h5
kill -KILL $pid; wait $pid 2>/dev/null
s=$(status killed.h5 run)
[[ $s == "running | none | "* ]] && ok "a killed run's file reads with swmr=True: $s" || bad "killed.h5: $s"
rfem_plot killed.h5 -o plots > /dev/null 2> err.txt && ls plots/run_joints.png > /dev/null 2>&1 \
  && ok "rfem plot draws a killed run" || bad "plot of a killed run: $(cat err.txt)"

# 9. A full disk (root only: a small tmpfs) ends the run as failed with the rows before it readable
#    (once: "completed", then a segfault and an unreadable file).
if [ "$(id -u)" = 0 ] && mkdir -p small && mount -t tmpfs -o size=250k tmpfs small 2>/dev/null; then
  "$rfem" --threads 1 run "$src/cases/two_link_arm.toml" --set simulation.t_end=5 -q -o small/out.h5 2> err.txt; code=$?
  one_line 1 "a 250 kB disk"
  s=$(status small/out.h5 run)
  [[ $s == "failed: cannot write "*"the disk is full"*" | "* ]] && ok "its file reads plainly: ${s:0:60}…${s: -20}" || bad "full disk: $s"
  umount small
else
  echo "skip a full disk (needs root to mount a small tmpfs)"
fi
(ulimit -f 200; "$rfem" --threads 1 run "$src/cases/two_link_arm.toml" --set simulation.t_end=5 -q -o fsize.h5 2> err.txt); code=$?
one_line 1 "ulimit -f 200"
s=$(status fsize.h5 run)
[[ $s == "failed: cannot write "*"file size limit"* ]] && ok "its file reads plainly: ${s:0:50}…" || bad "ulimit -f: $s"

# A file that cannot even be created whole (no room for its header) is not left behind empty
# (once: a 0-byte out.h5).
(ulimit -f 1; exec "$rfem" --threads 1 run "$src/cases/two_link_arm.toml" --set simulation.t_end=0.1 -q -o nofile.h5 2> err.txt); code=$?
one_line 2 "ulimit -f 1 (1 kB: room for this message, not for a file)"
[ ! -e nofile.h5 ] && ok "no empty file left" || bad "ulimit -f 0 left $(stat -c %s nofile.h5)-byte nofile.h5 (ulimit -f 1)"

[ $fail = 0 ] && echo "all passed" || echo "failures above"
exit $fail
