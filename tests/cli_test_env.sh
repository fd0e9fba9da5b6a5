# Sourced by the command-line tests: rfem is the binary given as $1, src the source tree, and the
# test runs in a temporary directory removed on exit (no result files land in the repository).
rfem=$(realpath "$1")
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
cd "$dir"
