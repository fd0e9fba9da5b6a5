#!/usr/bin/env bash
# rfem sweep: a 6-point sweep of Kane's spin-up over n and T gives the same table run one at a
# time, two at a time and (when built with MPI: $2 = 1) across 3 MPI ranks; its peaks converge with
# observed order 2 ± 0.3 in n at each T; a sweep killed with SIGKILL, or stopped by SIGINT (exit
# 130), leaves a valid index and a rerun redoes only what did not finish (the interrupted point
# from its checkpoint), ending with the uninterrupted table bit for bit; under MPI, SIGINT or
# SIGTERM to one worker rank ends the sweep the same way (exit 128 + signal, "N interrupted");
# a second sweep on an index another holds, an unwritable output and bad sweep files give one line
# and exit 2 with nothing touched; an index that cannot be written leaves no .tmp; rfem plot draws
# the index.
set -euo pipefail
source "$(dirname "$0")/cli_test_env.sh"
mpi=${2:-0}
# Under the sanitizers (\$3 = 1) the killed and interrupted sweeps use n = 100 (a point of n = 300
# takes ~25 s there, ~1 s in Release).
kill_n=$([ "${3:-0}" = 1 ] && echo 100 || echo 300)
cat > s.toml <<TOML
[sweep]
case = "$src/cases/kane_spinup.toml"
quantities = ["peak:u1", "tau1@3"]
set = ["simulation.t_end=3"]
[parameters]
n = [6, 12, 24]
"joints.0.input.T" = [10.0, 15.0]
TOML
"$rfem" sweep s.toml --jobs 1 -o one.h5 -q 2>/dev/null
"$rfem" sweep s.toml --jobs 2 -o two.h5 -q 2>/dev/null
runs="one two"
if [ "$mpi" = 1 ]; then
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n 3 --oversubscribe "$rfem" sweep s.toml -o mpi.h5 -q 2>/dev/null
  runs="one two mpi"
fi
RUNS="$runs" /usr/bin/python3 - <<'PY'
import os, sys
import h5py, numpy as np
files = {k: h5py.File(k + ".h5", "r") for k in os.environ["RUNS"].split()}
one = files["one"]
q, p = one["quantities"][()], one["parameters"][()]
checks = {
    "table": q.shape == (6, 2) and list(one["quantities"].attrs["columns"]) == ["peak:u1", "tau1@3"],
    # (parameters in key order, the last varying fastest)
    "parameters": p.tolist() == [[10, 6], [10, 12], [10, 24], [15, 6], [15, 12], [15, 24]],
    "all completed": list(one.attrs["status"]) == ["completed"] * 6,
    "external links resolve": all(one[f"runs/run000{k}/run"].attrs["status"] == "completed" for k in range(6)),
}
for k, f in files.items():  # each run single-threaded: bit for bit, whoever ran it
    checks[f"{k}: same table"] = np.array_equal(f["quantities"][()], q)
for T in (10, 15):  # second-order RFEM: the peak converges with order 2 in n
    u = q[p[:, 0] == T, 0]
    order = np.log(abs(u[1] - u[0]) / abs(u[2] - u[1])) / np.log(2)
    checks[f"T = {T}: order {order:.3f} within 2 ± 0.3"] = abs(order - 2) < 0.3
checks["a longer spin-up bends less"] = all(q[p[:, 0] == 15, 0] < q[p[:, 0] == 10, 0])
for k, v in checks.items():
    print(("ok  " if v else "FAIL"), k)
sys.exit(0 if all(checks.values()) else 1)
PY
# Killed (SIGKILL) and stopped (SIGINT) mid-sweep: points of ~1 s each, one at a time.
cat > k.toml <<TOML
[sweep]
case = "$src/cases/kane_spinup.toml"
quantities = ["peak:u1"]
set = ["simulation.t_end=4"]
checkpoint = 0.02
[parameters]
n = [$kill_n]
"joints.0.input.T" = [10.0, 11.0, 12.0, 13.0]
TOML
completed() { /usr/bin/python3 -c "import h5py; print(list(h5py.File('$1','r').attrs['status']).count('completed'))" 2>/dev/null || echo 0; }
# Waits until a point has finished and one that has not has written a checkpoint early in its run
# (≤ 32 of its 81 output rows): a signal then lands inside that point however fast points run (a
# fixed delay after the first point's end raced the next point's start).
wait_inside_a_later_point() {
  /usr/bin/python3 - <<'PY'
import os, sys, time
import h5py
end = time.time() + 600
while time.time() < end:
    try:
        with h5py.File("k.h5", "r") as f:
            status = [str(x) for x in f.attrs["status"]]
    except Exception:
        status = []
    if status and status.count("completed") == len(status):
        sys.exit(1)  # (every point ran: no later one left to catch)
    if 1 <= status.count("completed") < len(status):
        for k, st in enumerate(status):
            if st == "completed" or not os.path.exists(f"k.runs/run{k:04d}.h5"):
                continue
            try:
                with h5py.File(f"k.runs/run{k:04d}.h5", "r", swmr=True) as r:
                    slots = r["run/checkpoint"][:, :3]  # magic, sequence, rows
                if any(0 < s[2] <= 32 for s in slots if s[0] != 0):
                    sys.exit(0)
            except Exception:
                pass
    time.sleep(0.01)
sys.exit(1)
PY
}
for sig in KILL INT; do
  rm -rf k.h5 k.runs
  "$rfem" sweep k.toml --jobs 1 -q 2>/dev/null &
  pid=$!
  wait_inside_a_later_point || { echo "FAIL: SIG$sig: no point after the first wrote an early checkpoint"; exit 1; }
  kill -$sig "$pid"
  set +e
  wait "$pid"
  code=$?
  set -e
  want=$([ $sig = KILL ] && echo 137 || echo 130)
  [ "$code" = "$want" ] || { echo "FAIL: exit $code on SIG$sig (want $want)"; exit 1; }
  done_before=$(completed k.h5)
  [ "$done_before" -ge 1 ] && [ "$done_before" -lt 4 ] || { echo "FAIL: SIG$sig: $done_before points done in the index"; exit 1; }
  first=$(stat -c %Y.%N k.runs/run0000.h5 2>/dev/null || stat -c %Y k.runs/run0000.h5)
  "$rfem" sweep k.toml --jobs 1 -q 2>/dev/null
  [ "$(stat -c %Y.%N k.runs/run0000.h5 2>/dev/null || stat -c %Y k.runs/run0000.h5)" = "$first" ] || { echo "FAIL: SIG$sig: a finished point ran again"; exit 1; }
  [ "$(completed k.h5)" = 4 ] || { echo "FAIL: SIG$sig: the rerun did not finish the sweep"; exit 1; }
  resumed=$(/usr/bin/python3 -c "import h5py; print(h5py.File('k.runs/run000$done_before.h5')['run'].attrs.get('resumed_from_row', 0))")
  [ "$resumed" -gt 0 ] || { echo "FAIL: SIG$sig: the interrupted point did not go on from its checkpoint"; exit 1; }
  echo "ok   SIG$sig after $done_before of 4 points: exit $code, the rerun ran the other $((4 - done_before)), the interrupted one from its checkpoint (output $resumed)"
done
if [ "$mpi" = 1 ]; then  # a worker rank killed: OpenMPI ends the job; the rerun redoes what did not finish
  rm -rf k.h5 k.runs
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n 3 --oversubscribe "$rfem" sweep k.toml -q > /dev/null 2>&1 &
  pid=$!
  wait_inside_a_later_point || { echo "FAIL: killed rank: no point after the first wrote an early checkpoint"; exit 1; }
  worker=""
  for p in $(pgrep -f "^$rfem sweep k.toml"); do  # (a worker: rank 0 runs no point)
    [ "$(tr '\0' '\n' < /proc/$p/environ 2>/dev/null | sed -n 's/^OMPI_COMM_WORLD_RANK=//p')" = 1 ] && worker=$p
  done
  [ -n "$worker" ] || { echo "FAIL: killed rank: no rank 1 found"; exit 1; }
  kill -KILL "$worker"
  set +e
  wait "$pid"
  code=$?
  set -e
  done_before=$(completed k.h5)
  [ "$code" != 0 ] && [ "$done_before" -ge 1 ] && [ "$done_before" -lt 4 ] || { echo "FAIL: killed rank: exit $code, $done_before done"; exit 1; }
  OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n 3 --oversubscribe "$rfem" sweep k.toml -q 2>/dev/null
  [ "$(completed k.h5)" = 4 ] || { echo "FAIL: killed rank: the rerun did not finish the sweep"; exit 1; }
  echo "ok   a worker rank killed after $done_before of 4 points: mpirun exit $code, the rerun ran the other $((4 - done_before))"
  # SIGINT or SIGTERM to worker rank 1 alone (not to mpirun): the sweep stops as a local one does.
  for sig in INT TERM; do
    rm -rf k.h5 k.runs
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n 3 --oversubscribe "$rfem" sweep k.toml > mpi.out 2>/dev/null &
    pid=$!
    # (the index exists once every rank has installed its signal handlers; the first points run)
    for i in $(seq 1 6000); do [ -e k.h5 ] && break; kill -0 "$pid" 2>/dev/null || break; sleep 0.01; done
    worker=""
    for p in $(pgrep -f "^$rfem sweep k.toml"); do
      [ "$(tr '\0' '\n' < /proc/$p/environ 2>/dev/null | sed -n 's/^OMPI_COMM_WORLD_RANK=//p')" = 1 ] && worker=$p
    done
    [ -n "$worker" ] || { echo "FAIL: SIG$sig to a worker: no rank 1 found"; exit 1; }
    kill -$sig "$worker"
    set +e
    wait "$pid"
    code=$?
    set -e
    want=$([ $sig = INT ] && echo 130 || echo 143)
    # (completed, interrupted by the signal, anything else but pending)
    counts=$(/usr/bin/python3 -c "
import h5py; s = [str(x) for x in h5py.File('k.h5', 'r').attrs['status']]
i = s.count('interrupted (signal $((want - 128)))')
print(s.count('completed'), i, len(s) - s.count('completed') - s.count('pending') - i)")
    read -r n_done n_int n_other <<< "$counts"
    summary=$(tail -1 mpi.out)
    if [ "$code" != "$want" ] || [ "$n_done" = 4 ] || [ "$n_other" != 0 ] || { [ "$n_int" -gt 0 ] && ! grep -qF ", $n_int interrupted;" <<< "$summary"; }; then
      echo "FAIL: SIG$sig to worker rank 1: mpirun exit $code (want $want), index $counts, summary: $summary"; exit 1
    fi
    OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -n 3 --oversubscribe "$rfem" sweep k.toml -q 2>/dev/null
    [ "$(completed k.h5)" = 4 ] || { echo "FAIL: SIG$sig to a worker: the rerun did not finish the sweep"; exit 1; }
    echo "ok   SIG$sig to worker rank 1 after $n_done of 4 points: mpirun exit $code, $n_int interrupted ($summary); the rerun finished"
  done
fi
cp k.h5 resumed.h5
rm -rf k.h5 k.runs
"$rfem" sweep k.toml --jobs 2 -q 2>/dev/null &
pid=$!
# Meanwhile: a second sweep on this index is refused at once (exit 2, one line), the first untouched.
for i in $(seq 1 6000); do [ -e k.h5 ] && break; kill -0 "$pid" 2>/dev/null || break; sleep 0.01; done
set +e
"$rfem" sweep k.toml --jobs 2 -q > /dev/null 2> second.err
code=$?
wait "$pid"
first=$?
set -e
[ "$code" = 2 ] && [ "$(wc -l < second.err)" = 1 ] && grep -qF "k.h5: another sweep is writing this index" second.err && [ "$first" = 0 ] && [ "$(completed k.h5)" = 4 ] \
  || { echo "FAIL: two sweeps on one index: second exit $code ($(cat second.err)), first exit $first, $(completed k.h5) of 4 completed"; exit 1; }
echo "ok   a second sweep on the index: $(cat second.err)"
/usr/bin/python3 -c "
import h5py, numpy as np, sys
ok = np.array_equal(h5py.File('resumed.h5')['quantities'][()], h5py.File('k.h5')['quantities'][()])
print('ok   resumed table = uninterrupted' if ok else 'FAIL resumed table differs'); sys.exit(0 if ok else 1)"
# Bad sweep files: one line naming file, line and key (or the point), exit 2.
bad() {  # expect, then the file's text
  printf '%s\n' "$2" > bad.toml
  set +e
  "$rfem" sweep bad.toml -q > /dev/null 2> bad.err
  code=$?
  set -e
  if [ "$code" != 2 ] || [ "$(wc -l < bad.err)" != 1 ] || ! grep -qF -- "$1" bad.err; then
    echo "FAIL bad sweep ($1): exit $code: $(cat bad.err)"; exit 1
  fi
  echo "ok   bad sweep: $(cat bad.err)"
}
head='[sweep]
case = "'"$src"'/cases/kane_spinup.toml"'
q='quantities = ["peak:u1"]'
bad "bad.toml:3: sweep.quantity: unknown key" "$head
quantity = [\"peak:u1\"]
[parameters]
n = [4]"
bad "parameters.n: must be whole numbers" "$head
$q
[parameters]
n = [4.5]"
bad "has 3 values and 'joints.0.input.T' 2" "$head
$q
combine = \"zip\"
[parameters]
\"joints.0.input.T\" = [5.0, 6.0]
n = [4, 8, 16]"
bad "point 1 (joints.0.input.T=-1): " "$head
$q
[parameters]
\"joints.0.input.T\" = [5, -1]"
bad "peak:u9" "$head
quantities = [\"peak:u9\"]
[parameters]
n = [4]"
bad "parameters: missing table" "$head
$q"
bad "bad.toml:3: sweep.quantities: is empty: name at least one quantity" "$head
quantities = []
[parameters]
n = [4]"
bad "bad.toml:1: sweep.quantities: missing: name at least one quantity" "$head
[parameters]
n = [4]"
[ ! -e bad.h5.tmp ] && [ ! -e bad.h5 ] || { echo "FAIL: a refused sweep file left $(ls bad.h5*)"; exit 1; }
# Where the index cannot go (a file for a folder; a read-only folder where the user is not root):
# one line, exit 2, nothing written. Mid-sweep, an index that cannot be replaced: no .tmp left.
printf '%s\n' "$head" "$q" '[parameters]' 'n = [4]' > ok.toml
touch notdir
mkdir -p ro dir.h5 && chmod a-w ro
for out in notdir/i.h5 $(touch ro/probe 2>/dev/null || echo ro/i.h5) dir.h5; do
  set +e
  "$rfem" sweep ok.toml -q -o "$out" > /dev/null 2> out.err
  code=$?
  set -e
  [ "$code" = 2 ] && [ "$(wc -l < out.err)" = 1 ] && grep -qF "$out" out.err || { echo "FAIL: sweep -o $out: exit $code: $(cat out.err)"; exit 1; }
  echo "ok   sweep -o $out: $(cat out.err)"
done
rm -rf k.h5 k.runs
"$rfem" sweep k.toml --jobs 1 -q 2> k.err &
pid=$!
for i in $(seq 1 6000); do [ -f k.h5 ] && break; kill -0 "$pid" 2>/dev/null || break; sleep 0.01; done
until rm -f k.h5 && mkdir k.h5 2>/dev/null; do :; done  # (its next rename finds a folder)
set +e
wait "$pid"
code=$?
set -e
[ "$code" != 0 ] && grep -qF "k.h5: cannot write the index" k.err && [ ! -e k.h5.tmp ] || { echo "FAIL: an index that cannot be replaced: exit $code, $(ls -d k.h5*): $(cat k.err)"; exit 1; }
echo "ok   an index that cannot be replaced: exit $code, no k.h5.tmp: $(grep error k.err)"
rmdir k.h5
# The index plots: each quantity against each parameter, orders over n.
rfem_plot one.h5 -o figs > /dev/null
test -s figs/sweep_peak_u1_vs_n.png && test -s figs/sweep_tau1_3_vs_joints.0.input.T.png || { echo "FAIL: sweep figures"; ls figs; exit 1; }
echo "ok   rfem plot: $(ls figs | wc -l) figures"
