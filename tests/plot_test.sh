#!/usr/bin/env bash
# rfem plot writes every expected PNG for the paper's case (and the momentum of a free base), none
# is blank (pixel spread), and none for the tips of a run whose links are all rigid (it would be an
# empty plot); PDF on request.
set -euo pipefail
source "$(dirname "$0")/cli_test_env.sh"
"$rfem" run "$src/cases/paper_deployment.toml" --quiet --set simulation.t_end=4 -o paper.h5
rfem_plot paper.h5 -o figs >/dev/null
"$rfem" run "$src/cases/space_deployment.toml" --quiet --n 2 --set simulation.t_end=4 -o space.h5 2>/dev/null
rfem_plot space.h5 -o figs >/dev/null
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
if rfem_plot bad.h5 2>err.txt; then echo "FAIL: plot accepted a non-HDF5 file"; exit 1; fi
grep -q "rfem plot: error: bad.h5" err.txt || { echo "FAIL: message"; cat err.txt; exit 1; }
# Figures for print: PDF, with the paper's signs of u1, u2.
rfem_plot paper.h5 -o pdf --format pdf --paper-signs >/dev/null
head -c 4 pdf/fig5_tip.pdf | grep -q "%PDF" || { echo "FAIL: no PDF"; exit 1; }
echo "ok pdf"
# rfem plot calls the package's entry point (rfem.plots:main) found beside the program: not an rfem/
# in the current directory, and RFEM_PYTHONPATH, when set, must hold the package.
mkdir -p decoy/rfem && echo 'raise SystemExit("the rfem/ of the current directory was imported")' > decoy/rfem/__init__.py
(cd decoy && rfem_plot ../paper.h5 -o ../decoyfigs >/dev/null 2>err.txt) || { echo "FAIL: decoy package"; cat decoy/err.txt; exit 1; }
[ -s decoyfigs/fig5_tip.png ] || { echo "FAIL: no figures beside a decoy rfem/"; exit 1; }
echo "ok rfem/ of the current directory not imported"
if RFEM_PYTHONPATH=/nonexistent "$rfem" plot paper.h5 -o none 2>err.txt; then echo "FAIL: a wrong RFEM_PYTHONPATH accepted"; exit 1; fi
[ "$(wc -l < err.txt)" = 1 ] && grep -q "RFEM_PYTHONPATH=/nonexistent: no rfem/plots.py there" err.txt \
  || { echo "FAIL: RFEM_PYTHONPATH message"; cat err.txt; exit 1; }
echo "ok RFEM_PYTHONPATH checked"
