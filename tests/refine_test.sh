#!/usr/bin/env bash
# rfem refine with a dynamic quantity: the spin-up peak tip deflection converges with observed order
# ≈ 2 over n = 6, 12, 24 (second-order RFEM), every run and the table land in one HDF5 file, and
# rfem plot draws its convergence figure.
set -euo pipefail
source "$(dirname "$0")/cli_test_env.sh"
"$rfem" refine "$src/cases/kane_spinup.toml" --n 6,12,24 --quantity peak:u1 --set simulation.t_end=8 -q -o ref.h5 --json > ref.json
/usr/bin/python3 - <<'PY'
import json, sys, h5py
rows = json.load(open("ref.json"))["rows"]
order = rows[-1]["order"]
f = h5py.File("ref.h5", "r")
groups = sorted(k for k in f.keys() if k.startswith("n"))
ok = 1.7 < order < 2.3 and groups == ["n12", "n24", "n6"] and list(f["refine/n"][:]) == [6, 12, 24] \
     and str(f["n24/run"].attrs["status"].decode() if isinstance(f["n24/run"].attrs["status"], bytes) else f["n24/run"].attrs["status"]) == "completed"
print("observed order", order, "groups", groups, "->", "ok" if ok else "FAIL")
sys.exit(0 if ok else 1)
PY
"$rfem" plot ref.h5 -o figs >/dev/null
test -s figs/refine_convergence.png && echo "1 passed, 0 failed"
