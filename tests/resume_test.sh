#!/usr/bin/env bash
# rfem run --resume: Kane's spin-up at n = 400 (n = 40 under the sanitizers: $2 = 1) killed with
# SIGKILL after its first checkpoint, another stopped with SIGINT (exit 130), a third killed after
# its third checkpoint with the newest one torn, each resumed from its results file, end with every
# dataset bit for bit that of the uninterrupted run (ESDIRK, one thread); a BDF run killed and
# resumed stays within BDF's own error of its uninterrupted run; a finished file resumes to nothing;
# bad resumes give one line and exit 2.
set -euo pipefail
source "$(dirname "$0")/cli_test_env.sh"
# Under the sanitizers ($2 = 1) n = 40: a run of n = 100 takes ~30 s there; the code paths are the same.
n=$([ "${2:-0}" = 1 ] && echo 40 || echo 400)
"$rfem" --threads 1 run "$src/cases/kane_spinup.toml" --n "$n" -o full.h5 -q
RFEM="$rfem" SRC="$src" N="$n" /usr/bin/python3 - <<'PY'
import os, signal, subprocess, sys, time
import h5py, numpy as np

rfem, case, n = os.environ["RFEM"], os.environ["SRC"] + "/cases/kane_spinup.toml", os.environ["N"]
every = "0.2"  # s of wall time between checkpoints
checks = {}

def datasets(path):
    out = {}
    with h5py.File(path, "r") as f:
        f.visititems(lambda k, v: out.__setitem__(k, v[()]) if isinstance(v, h5py.Dataset) else None)
    return out

def checkpoints(path):  # how many checkpoints the run has written (read as SWMR while it goes)
    try:
        with h5py.File(path, "r", swmr=True) as f:
            c = f["run/checkpoint"]
            return int(c[:, 1].max()) if c.shape[1] > 0 else 0
    except (OSError, KeyError):
        return 0

full = datasets("full.h5")
# Killed after its first checkpoint; interrupted; killed after its third with the newest one torn
# (as by a kill while it was written: the older slot is used).
for sig, code, torn in ((signal.SIGKILL, -9, False), (signal.SIGINT, 130, False), (signal.SIGKILL, -9, True)):
    out = f"{sig.name}{'_torn' if torn else ''}.h5"
    name = out[:-3]
    p = subprocess.Popen([rfem, "--threads", "1", "run", case, "--n", n, "-o", out, "-q", "--checkpoint", every])
    t0 = time.time()
    while checkpoints(out) < (3 if torn else 1) and p.poll() is None and time.time() - t0 < 120:
        time.sleep(0.05)
    p.send_signal(sig)
    rc = p.wait()
    with h5py.File(out, "r", swmr=True) as f:
        rows = f["run/time"].shape[0]
    checks[f"{name}: stopped mid-run (exit {rc}, {rows} of {len(full['run/time'])} outputs)"] = (
        rc == code and 0 < rows < len(full["run/time"]))
    if torn:  # one state value of the newest slot changed in the file's bytes (HDF5 cannot open it to write)
        with h5py.File(out, "r", swmr=True) as f:
            c = f["run/checkpoint"]
            newest = int(np.argmax(c[:, 1]))
            head = c[newest, :2]  # magic, sequence: where the slot starts in the file
            older_rows = int(c[1 - newest, 2])
        data = open(out, "rb").read()
        start = data.find(head.astype("<f8").tobytes())
        assert start >= 0, "the newest slot is not in the file"
        with open(out, "r+b") as raw:
            raw.seek(start + 20 * 8)
            raw.write((np.frombuffer(data[start + 160:start + 168], dtype="<f8") + 1.0).tobytes())
    r = subprocess.run([rfem, "--threads", "1", "run", "--resume", out], capture_output=True, text=True)
    checks[f"{name}: --resume exits 0"] = r.returncode == 0 and "goes on from its checkpoint" in r.stdout
    if torn:
        checks[f"{name}: goes on from the older checkpoint ({older_rows} outputs kept)"] = f"({older_rows} outputs kept)" in r.stdout
    got = datasets(out)
    same = [k for k in full if "checkpoint" not in k and "status_now" not in k]
    checks[f"{name}: {len(same)} datasets bit for bit the uninterrupted run's"] = all(
        k in got and got[k].shape == full[k].shape and np.array_equal(got[k], full[k]) for k in same)
    with h5py.File(out, "r") as f, h5py.File("full.h5", "r") as g:
        checks[f"{name}: status, steps, residuals as uninterrupted"] = all(
            f["run"].attrs[a] == g["run"].attrs[a] for a in ("status", "steps", "residual_evals", "t_reached"))
# BDF (IDA) restarts at its checkpoint with a fresh history: not bit for bit, but the resumed run
# must stay closer to the uninterrupted one than that is to ESDIRK's solution (BDF2's own error at
# these tolerances; measured: 1 % of it).
bdf = ["--set", "simulation.integrator=bdf"]
subprocess.run([rfem, "--threads", "1", "run", case, "--n", n, "-o", "bdf_full.h5", "-q"] + bdf, check=True)
p = subprocess.Popen([rfem, "--threads", "1", "run", case, "--n", n, "-o", "bdf.h5", "-q", "--checkpoint", every] + bdf)
t0 = time.time()
while checkpoints("bdf.h5") < 1 and p.poll() is None and time.time() - t0 < 120:
    time.sleep(0.05)
p.kill()
p.wait()
r = subprocess.run([rfem, "--threads", "1", "run", "--resume", "bdf.h5"], capture_output=True, text=True)
with h5py.File("bdf.h5") as f, h5py.File("bdf_full.h5") as g, h5py.File("full.h5") as e:
    resumed, whole, esdirk = f["run/tip"][()], g["run/tip"][()], e["run/tip"][()]
    gap, own = np.abs(resumed - whole).max(), np.abs(whole - esdirk).max()
    checks[f"bdf: resumed (from output {f['run'].attrs.get('resumed_from_row', 0)}) within {gap:.2e} m of "
           f"the uninterrupted run, whose own error is {own:.2e} m"] = (
        r.returncode == 0 and f["run"].attrs["status"] == "completed" and f["run"].attrs.get("resumed_from_row", 0) > 0
        and resumed.shape == whole.shape and gap < 0.5 * own)
r = subprocess.run([rfem, "run", "--resume", "SIGKILL.h5"], capture_output=True, text=True)
checks["a finished file resumes to nothing"] = r.returncode == 0 and "nothing to do" in r.stdout
for k, v in checks.items():
    print(("ok  " if v else "FAIL"), k)
sys.exit(0 if all(checks.values()) else 1)
PY
# Bad resumes: one line on stderr, exit 2.
echo "not hdf5" > junk.h5
"$rfem" refine "$src/cases/kane_spinup.toml" --n 6,12 --set simulation.t_end=0.5 --quantity peak:u1 -o refine.h5 -q >/dev/null 2>&1
for bad in missing.h5 junk.h5 refine.h5; do
  set +e
  err=$("$rfem" run --resume "$bad" 2>&1 >/dev/null)
  rc=$?
  set -e
  if [ "$rc" != 2 ] || [ "$(printf '%s\n' "$err" | wc -l)" != 1 ]; then
    echo "FAIL --resume $bad: exit $rc, stderr: $err"
    exit 1
  fi
  echo "ok   --resume $bad: $err"
done
