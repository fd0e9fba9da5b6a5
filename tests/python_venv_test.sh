#!/usr/bin/env bash
# The package as a user installs it: `pip install --no-build-isolation` of the checkout (pyproject.toml,
# setup.py) into a fresh virtual environment, taking the module and librfem from this build directory
# (RFEM_BUILD_DIR, RFEM_NO_BUILD: seconds, nothing compiled); `import rfem` and a tiny run from
# another directory with the environment's python, a shipped case by its name; the checked-in stubs (python/rfem/_rfem.pyi) are
# what the installed module gives (scripts/make_stubs.py --check).
#   bash tests/python_venv_test.sh BUILD_DIR
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:?usage: python_venv_test.sh BUILD_DIR}" && pwd)
py=${RFEM_TEST_PYTHON:-/usr/bin/python3}
if ! "$py" -c "import venv, ensurepip" 2>/dev/null; then
  echo "skipped: no venv/ensurepip for $py (Debian: apt-get install python3-venv)"; exit 0
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
unset PYTHONPATH LD_LIBRARY_PATH PIP_REQUIRE_VIRTUALENV

start=$SECONDS
if ! "$py" -m venv --system-site-packages "$work/venv" >"$work/venv.log" 2>&1; then
  if grep -q ensurepip "$work/venv.log"; then  # (Debian: pip's wheel, python3-pip-whl, is missing)
    echo "skipped: $py -m venv has no pip: $(tail -n1 "$work/venv.log")"; exit 0
  fi
  cat "$work/venv.log"; echo "FAIL: $py -m venv"; exit 1
fi
venv_py=$work/venv/bin/python
(cd "$work" && RFEM_BUILD_DIR=$build RFEM_NO_BUILD=1 "$work/venv/bin/pip" install --no-build-isolation --no-index \
   --disable-pip-version-check -q "$src" >"$work/pip.log" 2>&1) || { cat "$work/pip.log"; echo "FAIL: pip install"; exit 1; }
echo "pip install: $((SECONDS - start)) s"

mkdir "$work/elsewhere"
cd "$work/elsewhere"
"$venv_py" - "$src" <<'EOF'
import glob, importlib.metadata, math, os, subprocess, sys
src = sys.argv[1]
import rfem
here = os.path.dirname(rfem.__file__)
assert here.startswith(sys.prefix + os.sep), f"rfem imported from {here}, not from the venv {sys.prefix}"
assert rfem.__version__ == importlib.metadata.version("rfem"), (rfem.__version__, importlib.metadata.version("rfem"))
missing = [os.path.basename(f) for f in glob.glob(os.path.join(src, "python", "rfem", "*.py"))
           if not os.path.exists(os.path.join(here, os.path.basename(f)))]
missing += [f for f in ("py.typed", "_rfem.pyi") if not os.path.exists(os.path.join(here, f))]
assert not missing, f"not installed: {missing}"
ldd = subprocess.run(["ldd", rfem._rfem.__file__], capture_output=True, text=True).stdout
for line in ldd.splitlines():  # librfem (when shared) from beside _rfem
    if "librfem" in line:
        assert os.path.join(here, "") in line, f"_rfem loads {line.strip()}"
# The shipped cases by name, from the installed package (not the checkout: this is another folder).
assert "kane_spinup" in rfem.cases and "paper_deployment" in rfem.cases, rfem.cases
assert rfem.case_path("kane_spinup").startswith(here + os.sep) and os.path.isfile(os.path.join(here, "cases", "urdf", "three_link_arm.urdf"))
assert rfem.load("urdf_arm").name == "urdf_arm"  # (its URDF file found beside it)
runs = rfem.run(rfem.load("kane_spinup", {"simulation.t_end": 2.0}), n=4)
u1 = runs["run"].column("tip_deflection", 0)
assert runs.completed and all(math.isfinite(x) for x in u1), runs["run"].status
assert 1e-3 < abs(u1).max() < 1.0, f"tip deflection {abs(u1).max()} m"  # the spin-up bends the 10 m beam by ~0.1 m
print(f"venv: rfem {rfem.__version__} from {os.path.relpath(here, sys.prefix)}, run {runs['run'].status}, "
      f"peak tip deflection {abs(u1).max():.4f} m")
EOF
"$venv_py" "$src/scripts/make_stubs.py" --check --from "$(dirname "$("$venv_py" -c 'import rfem, os; print(os.path.dirname(rfem.__file__))')")"
# The package's console scripts: installed, and the same commands as the program's (a file it cannot
# read: one line, exit 2).
for c in rfem-plot rfem-animate rfem-bode; do [[ -x $work/venv/bin/$c ]] || { echo "FAIL: no $c in the venv"; exit 1; }; done
set +e; msg=$("$work/venv/bin/rfem-bode" "$work/none.h5" --input hub --output hub/q 2>&1 >/dev/null); code=$?; set -e
[[ $code == 2 && $msg == "rfem bode: error: "* && $(wc -l <<<"$msg") == 1 ]] || { echo "FAIL: rfem-bode on a missing file: exit $code: $msg"; exit 1; }
echo "python_venv: ok ($((SECONDS - start)) s)"
