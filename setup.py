"""The extension rfem._rfem for `pip install --no-build-isolation .`, built by the project's own CMake.

Metadata is in pyproject.toml; the version is CMakeLists.txt's project(rfem VERSION ...). The wheel
holds every python/rfem/*.py, py.typed and the stubs (_rfem.pyi: scripts/make_stubs.py), the shipped
cases (rfem/cases: cases/*.toml and their URDF files), the module _rfem as CMake built it, and librfem when it is a shared library, next to _rfem, which finds it
through its RUNPATH, set to $ORIGIN (CMake's own ELF editing; no patchelf). Nothing is written into
the source tree but build-python/ (gitignored), and nothing at all with RFEM_BUILD_DIR.

Environment:
  RFEM_BUILD_DIR    a configured build directory of this checkout (absolute, or relative to the
                    checkout: build): only its target _rfem is brought up to date and taken,
                    nothing compiled twice; setuptools' build tree goes in it (python-wheel/).
                    Unset: a build directory of the _rfem target alone in build-python/
                    (gitignored), reused by the next install.
  RFEM_NO_BUILD=1   with RFEM_BUILD_DIR: take its files as they are (no CMake run in it).
  RFEM_CMAKE_ARGS   more arguments for configuring the fresh build directory (-DRFEM_NATIVE=ON ...).
"""
import importlib.machinery
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
PACKAGE_DIR = ROOT / "python" / "rfem"


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    m = re.search(r"project\s*\(\s*rfem\s+VERSION\s+([0-9][0-9.]*)", text)
    if not m:
        sys.exit("setup.py: no project(rfem VERSION ...) in CMakeLists.txt")
    return m.group(1)


def run(cmd, **kwargs):
    print("setup.py: " + " ".join(shlex.quote(str(c)) for c in cmd), flush=True)
    subprocess.run([str(c) for c in cmd], check=True, **kwargs)


def cache_value(build_dir, key):
    for line in (build_dir / "CMakeCache.txt").read_text().splitlines():
        if line.startswith(key + ":"):
            return line.split("=", 1)[1]
    return None


def shared_libraries(module, build_dir):
    """The libraries of build_dir that module needs ({soname: path}), as the loader finds them."""
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    out = subprocess.run(["ldd", str(module)], check=True, capture_output=True, text=True, env=env).stdout
    libs = {}
    for line in out.splitlines():
        m = re.match(r"\s*(\S+)\s+=>\s+(.*?)\s+\(0x", line) or re.match(r"\s*(\S+)\s+=>\s+(not found)", line)
        if not m:
            continue
        name, path = m.groups()
        if path == "not found":
            if name.startswith("librfem"):
                raise RuntimeError(f"{module} needs {name}, which is not in {build_dir}")
            continue
        real = Path(path).resolve()
        if build_dir in real.parents:
            libs[name] = real
    return libs


class BuildPy(build_py):
    """The package afresh each time (no module a previous build left)."""

    def run(self):
        shutil.rmtree(Path(self.build_lib) / "rfem", ignore_errors=True)
        super().run()


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        temp = Path(self.build_temp).resolve()
        given = os.environ.get("RFEM_BUILD_DIR")
        if given:
            build_dir = Path(given).resolve()
            if not (build_dir / "CMakeCache.txt").is_file():
                raise RuntimeError(f"RFEM_BUILD_DIR={given}: not a configured CMake build directory (no CMakeCache.txt)")
            home = cache_value(build_dir, "CMAKE_HOME_DIRECTORY")
            if home and Path(home).resolve() != ROOT:
                raise RuntimeError(f"RFEM_BUILD_DIR={given} builds {home}, not this checkout ({ROOT})")
            if os.environ.get("RFEM_NO_BUILD") != "1":
                run(["cmake", "--build", build_dir, "--target", "_rfem", "-j", str(self.parallel or os.cpu_count() or 1)])
        else:
            build_dir = temp / "cmake"
            configure = ["cmake", "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release",
                         f"-DPython3_EXECUTABLE={sys.executable}", "-DRFEM_BUILD_PYTHON=ON",
                         "-DRFEM_BUILD_TESTS=OFF", "-DRFEM_BUILD_BENCH=OFF"]
            if not (build_dir / "CMakeCache.txt").exists() and shutil.which("ninja"):
                configure += ["-G", "Ninja"]
            run(configure + shlex.split(os.environ.get("RFEM_CMAKE_ARGS", "")))
            print("setup.py: compiling librfem and _rfem (several minutes the first time)", flush=True)
            run(["cmake", "--build", build_dir, "--target", "_rfem", "-j", str(self.parallel or os.cpu_count() or 1)])

        # The module as built (with the interpreter's suffix: a build for another Python fails here).
        names = ["_rfem" + s for s in importlib.machinery.EXTENSION_SUFFIXES if s.endswith(".so")]
        own = Path(BUILD_BASE).resolve()  # (setuptools' tree, in RFEM_BUILD_DIR, holds earlier copies)
        built = [build_dir / "python" / "rfem" / n for n in names if (build_dir / "python" / "rfem" / n).is_file()] or \
            sorted(p for n in names for p in build_dir.rglob(n)
                   if p.is_file() and p.parent.name == "rfem" and own not in p.parents)
        if not built:
            raise RuntimeError(f"no {names[0]} in {build_dir}: not built for this Python ({sys.executable})? "
                               "(its module needs pybind11-dev and python3-dev; configure with -DPython3_EXECUTABLE)")
        module = built[0]
        dest = Path(self.get_ext_fullpath(ext.name)).parent
        dest.mkdir(parents=True, exist_ok=True)
        shutil.copy2(module, dest / module.name)
        # The shipped cases as CMake copied them beside the module (python/CMakeLists.txt): rfem.cases.
        shutil.rmtree(dest / "cases", ignore_errors=True)
        shutil.copytree(module.parent / "cases", dest / "cases")

        # librfem (if shared) beside _rfem, found through $ORIGIN wherever the package goes.
        for name, path in sorted(shared_libraries(module, build_dir).items()):
            shutil.copy2(path, dest / name)
        temp.mkdir(parents=True, exist_ok=True)
        rpath_script = temp / "set_rpath.cmake"
        rpath_script.write_text('file(RPATH_SET FILE "${F}" NEW_RPATH "$ORIGIN")\n')
        try:
            run(["cmake", f"-DF={dest / module.name}", "-P", rpath_script], stdout=subprocess.DEVNULL)
        except subprocess.CalledProcessError:  # (CMake before 3.21, or no RUNPATH to rewrite)
            if not shutil.which("patchelf"):
                raise RuntimeError(f"cannot set the RUNPATH of {dest / module.name} to $ORIGIN (CMake >= 3.21 or patchelf)")
            run(["patchelf", "--set-rpath", "$ORIGIN", dest / module.name])
        missing = [l.strip() for l in subprocess.run(["ldd", str(dest / module.name)], capture_output=True, text=True,
                                                      env={k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
                                                      ).stdout.splitlines() if "not found" in l]
        if missing:
            raise RuntimeError(f"{dest / module.name} does not find {missing}")


# setuptools' build tree: in RFEM_BUILD_DIR when given (the sources untouched), else build-python/.
BUILD_BASE = os.path.join(os.environ["RFEM_BUILD_DIR"], "python-wheel") if os.environ.get("RFEM_BUILD_DIR") \
    else os.path.join(ROOT, "build-python")
os.makedirs(BUILD_BASE, exist_ok=True)
setup(
    version=project_version(),
    ext_modules=[Extension("rfem._rfem", sources=[])],
    cmdclass={"build_ext": CMakeBuild, "build_py": BuildPy},
    # setuptools' own build tree, the fresh CMake build and rfem.egg-info outside the sources and build/.
    options={"build": {"build_base": BUILD_BASE}, "egg_info": {"egg_base": BUILD_BASE}},
)
