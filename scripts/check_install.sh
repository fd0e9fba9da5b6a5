#!/usr/bin/env bash
# The installed package from outside: Examples 6 and 12 (examples/cpp) configured with find_package(rfem)
# against $RFEM_PREFIX (default /usr/local), built, run, and compared with its answer file; and
# `import rfem` from /usr/bin/python3 without any path set.
set -euo pipefail
cd "$(dirname "$0")/.."
prefix=${RFEM_PREFIX:-/usr/local}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cmake -S examples/cpp -B "$work" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work" 2>&1 | { grep -v '^\[[0-9]*/[0-9]*\] ' || true; }
/usr/bin/python3 examples/run_examples.py --only ex6,ex12 --cpp "$work"
(cd / && env -u PYTHONPATH /usr/bin/python3 -c "import rfem, sys; print('import rfem:', rfem.__version__, 'from', rfem.__file__)")
