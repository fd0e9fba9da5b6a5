#!/usr/bin/env bash
# Runs the bad-case corpus: every NN_*.toml in this directory must make rfem exit with code 2 and
# print exactly one line on stderr containing the file's `# expect:` substring.
#
#   usage: tests/bad_cases/run_corpus.sh path/to/rfem [NN_name ...]
#
# Each case file starts with
#   # expect: <substring of the one-line error message>
#   # command: static | modes | run  (and options: modes --n 1)
# Cases run in a fresh temporary directory (results files never land in the repository); files a
# case leaves behind are reported as a note. Prints `ok NN_name` or `FAIL NN_name: <why>` per
# file and `N passed, M failed`; exits 1 if any case failed.
set -u

if [[ $# -lt 1 ]]; then
  echo "usage: $0 path/to/rfem [NN_name ...]" >&2
  exit 2
fi
rfem=$1
shift
if [[ $rfem != /* ]]; then rfem="$PWD/$rfem"; fi
if [[ ! -x $rfem ]]; then
  echo "run_corpus.sh: '$rfem' is not an executable" >&2
  exit 2
fi
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
timeout_s=${RFEM_CORPUS_TIMEOUT:-120}

cases=()
if [[ $# -gt 0 ]]; then
  for name in "$@"; do cases+=("$here/${name%.toml}.toml"); done
else
  shopt -s nullglob
  cases=("$here"/[0-9][0-9]_*.toml "$here"/[0-9][0-9][0-9]_*.toml)
fi
if [[ ${#cases[@]} -eq 0 ]]; then
  echo "run_corpus.sh: no case files in $here" >&2
  exit 2
fi

scratch=$(mktemp -d "${TMPDIR:-/tmp}/rfem_bad_cases.XXXXXX")
trap 'rm -rf "$scratch"' EXIT

passed=0
failed=0
for file in "${cases[@]}"; do
  name=$(basename "$file" .toml)
  if [[ ! -f $file ]]; then
    echo "FAIL $name: no such case file"
    failed=$((failed + 1))
    continue
  fi
  expect=$(sed -n '1,5s/^# expect: //p' "$file" | head -n 1)
  command=$(sed -n '1,5s/^# command: //p' "$file" | head -n 1)
  if [[ -z $expect || -z $command ]]; then
    echo "FAIL $name: missing '# expect:' or '# command:' line"
    failed=$((failed + 1))
    continue
  fi
  work="$scratch/$name"
  mkdir -p "$work"
  # (the outer 2>/dev/null silences bash's own "Segmentation fault" report; rfem's stderr goes to .err)
  # (`# command:` may carry options: "modes --n 1")
  # shellcheck disable=SC2086
  { (cd "$work" && exec timeout "$timeout_s" "$rfem" $command "$file") >"$scratch/$name.out" 2>"$scratch/$name.err"; } 2>/dev/null
  rc=$?
  err=$(cat "$scratch/$name.err")
  lines=$(awk 'END { print NR }' "$scratch/$name.err")
  why=""
  if [[ $rc -eq 124 ]]; then
    why="timed out after ${timeout_s} s"
  elif [[ $rc -ge 128 ]]; then
    why="crashed: exit code $rc (signal $((rc - 128)))"
  elif [[ $rc -ne 2 ]]; then
    why="exit code $rc, expected 2"
  elif [[ $lines -ne 1 ]]; then
    why="$lines lines on stderr, expected 1"
  elif [[ $err != "rfem: error: "* ]]; then
    why="stderr does not start with 'rfem: error: '"
  elif [[ $err != *"$expect"* ]]; then
    why="stderr lacks '$expect'"
  fi
  if [[ -n $why ]]; then
    first=$(head -n 1 "$scratch/$name.err")
    echo "FAIL $name: $why${first:+ [stderr: $first]}"
    failed=$((failed + 1))
  else
    left=$(ls -A "$work")
    if [[ -n $left ]]; then
      echo "ok $name (note: left files behind: $(echo $left))"
    else
      echo "ok $name"
    fi
    passed=$((passed + 1))
  fi
done
echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
