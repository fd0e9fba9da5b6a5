# Sourced by the command-line tests: rfem is the binary given as $1, src the source tree, and the
# test runs in a temporary directory removed on exit (no result files land in the repository).
rfem=$(realpath "$1")
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
# `rfem plot` calls the package's entry point (rfem.plots:main) inside the program; a build without
# Python (the sanitizer build) has only the entry point itself, run by python3.
probe=$("$rfem" plot /dev/null 2>&1 || true)  # (exit 2 either way: /dev/null is no results file)
if [[ $probe == *"built without Python"* ]]; then
  rfem_plot() { /usr/bin/python3 -P -m rfem.plots "$@"; }
else
  rfem_plot() { "$rfem" plot "$@"; }
fi
