#!/usr/bin/env bash
# rfem plot writes every expected PNG for the paper's case (and the momentum of a free base), none
# is blank (pixel spread), and none for the tips of a run whose links are all rigid (it would be an
# empty plot); PDF on request.
set -euo pipefail
source "$(dirname "$0")/cli_test_env.sh"
"$rfem" run "$src/cases/paper_deployment.toml" --quiet --set simulation.t_end=4 -o paper.h5
"$rfem" plot paper.h5 -o figs >/dev/null
"$rfem" run "$src/cases/space_deployment.toml" --quiet --n 2 --set simulation.t_end=4 -o space.h5 2>/dev/null
"$rfem" plot space.h5 -o figs >/dev/null
/usr/bin/python3 - figs <<'PY'
import sys, os
import matplotlib.image as mpimg
d = sys.argv[1]
expected = ["fig5_tip", "fig6_torque3", "fig7_velocity3", "fig8_accel12"] + \
    [f"{g}_{k}" for g in ("rigid", "kinematic", "force") for k in ("joints", "tip", "energy") if (g, k) != ("rigid", "tip")] + \
    ["run_momentum"]
bad = 0
for name in expected:
    path = os.path.join(d, name + ".png")
    if not os.path.exists(path):
        print("FAIL missing", path); bad += 1; continue
    img = mpimg.imread(path)
    if img.std() < 0.02:
        print("FAIL blank", path); bad += 1
    else:
        print("ok", name)
if os.path.exists(os.path.join(d, "rigid_tip.png")):
    print("FAIL rigid_tip.png: a run with rigid links only has no tip deflections"); bad += 1
print(f"{len(expected) - bad} passed, {bad} failed")
sys.exit(1 if bad else 0)
PY
# An unreadable results file: one-line error, exit 2.
echo "not hdf5" > bad.h5
if "$rfem" plot bad.h5 2>err.txt; then echo "FAIL: plot accepted a non-HDF5 file"; exit 1; fi
grep -q "rfem plot: error: bad.h5" err.txt || { echo "FAIL: message"; cat err.txt; exit 1; }
# Figures for print: PDF, with the paper's signs of u1, u2.
"$rfem" plot paper.h5 -o pdf --format pdf --paper-signs >/dev/null
head -c 4 pdf/fig5_tip.pdf | grep -q "%PDF" || { echo "FAIL: no PDF"; exit 1; }
echo "ok pdf"
