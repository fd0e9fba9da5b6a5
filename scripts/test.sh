#!/usr/bin/env bash
# Installs the dependencies (Debian 12, root), builds rfem (Release) and installs it, runs the unit
# tests (C++, command line, Python, examples against their answers), then builds Example 6 as an
# external project against the installed CMake package and checks its answer.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j "$(nproc)" -L unit
bash scripts/check_install.sh
