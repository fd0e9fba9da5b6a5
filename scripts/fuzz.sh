#!/usr/bin/env bash
# libFuzzer on the case reader (clang, ASan + UBSan), a bounded 60 s run: CTest label `fuzz`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRFEM_FUZZ=ON \
  -DRFEM_BUILD_TESTS=OFF -DRFEM_BUILD_BENCH=OFF -DRFEM_BUILD_PYTHON=OFF >/dev/null
cmake --build build-fuzz -j "$(nproc)" --target fuzz_case_reader
ctest --test-dir build-fuzz --output-on-failure -L fuzz
