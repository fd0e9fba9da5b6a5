#!/usr/bin/env bash
# Installs the dependencies (Debian 12, root), builds and installs rfem (program, library, Python
# module) and runs the main examples: the paper's deployment and its figures, the two-link flexible
# arm, Kane's beam modes and refinement, the paper's link 3 modes, a static tip load, and the same
# arm from Python.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh rfem _rfem
set -x
build/apps/rfem run cases/paper_deployment.toml -o paper_deployment.h5 --set simulation.store_flexible_every=1
build/apps/rfem plot paper_deployment.h5 -o figures
build/apps/rfem run cases/two_link_arm.toml -o two_link_arm.h5
build/apps/rfem plot two_link_arm.h5 -o figures
build/apps/rfem modes cases/kane_beam.toml --count 8
build/apps/rfem refine cases/kane_beam.toml --n 5,10,20,40,80 --quantity bending-y:1
build/apps/rfem static cases/kane_beam.toml
build/apps/rfem modes cases/paper_link3.toml --n 60 --count 8
build/apps/rfem modes cases/kane_spinup.toml --rate 6 --count 4
/usr/bin/python3 examples/ex5_two_link_pd.py
set +x
echo
echo "== done: built build/apps/rfem and the Python module (installed under ${RFEM_PREFIX:-/usr/local});"
echo "   wrote paper_deployment.h5 (and its ParaView files paper_deployment.*.xdmf), two_link_arm.h5 and $(ls figures | wc -l) figures in figures/:"
ls figures | sed 's/^/     /'
