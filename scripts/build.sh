#!/usr/bin/env bash
# Dependencies, the Release build in build/ (TARGETS: the given targets, default all), and the
# library, program, plot script and Python module installed under $RFEM_PREFIX (default /usr/local,
# as root), where /usr/bin/python3 finds `import rfem` in any new shell. Shared by example.sh and test.sh.
#   bash scripts/build.sh [TARGET …]
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# A build/ configured for another path (a copied checkout) would stop CMake at once: start afresh.
if [[ -f build/CMakeCache.txt ]] && ! grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$(pwd -P)" build/CMakeCache.txt \
   && ! grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$(pwd)" build/CMakeCache.txt; then
  echo "build: build/ belongs to another checkout; configuring it afresh"
  rm -rf build
fi
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
echo "build: compiling (about 5 min on 2 cores the first time; warnings and errors only below)"
# Ninja's progress lines say nothing a reader needs; warnings and errors still show.
cmake --build build -j "$(nproc)" "${targets[@]}" 2>&1 | { grep -v '^\[[0-9]*/[0-9]*\] ' || true; }
prefix=${RFEM_PREFIX:-/usr/local}
if [[ -w $prefix || $EUID == 0 ]]; then
  cmake --install build --prefix "$prefix" >/dev/null
  command -v ldconfig >/dev/null && ldconfig 2>/dev/null || true
  echo "build: installed rfem $(build/apps/rfem --version | cut -d' ' -f2) in $prefix (program, library, headers, CMake package, Python module)"
else
  echo "build: $prefix is not writable: not installed (PYTHONPATH=$(pwd)/build/python for the Python module)"
fi
