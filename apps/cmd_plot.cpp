// `rfem plot`, `animate` and `bode` call the Python package's entry points (rfem.plots:main,
// rfem.animate:main, rfem.linear:main: the console scripts rfem-plot, rfem-animate, rfem-bode) in
// an interpreter embedded in the program (pybind11/embed.h; Debian's python3 with its matplotlib
// and h5py): no second process. The package is the one beside the program — installed,
// bin/../lib/python3.X/dist-packages; in the build tree, apps/../python (RFEM_PYTHON_DIRS, from
// python/CMakeLists.txt) — or in $RFEM_PYTHONPATH, or else an installed one on Python's own path;
// never an rfem/ in the current directory. A build without Python (RFEM_BUILD_PYTHON=OFF, the
// sanitizer build) says so.
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "commands.hpp"

#ifdef RFEM_HAVE_PYTHON
#include <pybind11/embed.h>
#include <pybind11/stl.h>
#endif

#ifndef RFEM_PYTHON_DIRS  // ':'-separated, relative to the program's directory (or absolute)
#define RFEM_PYTHON_DIRS "../python"
#endif

namespace rfem::app {

namespace {
namespace fs = std::filesystem;

// The directory holding the package rfem (with rfem/MODULE.py): $RFEM_PYTHONPATH, or the first of
// RFEM_PYTHON_DIRS beside the program that has it, or "" to leave it to Python's own path (an
// installed package); `looked` says where it looked.
std::string package_parent(const std::string& module, std::string& looked) {
  std::error_code ec;
  if (const char* e = std::getenv("RFEM_PYTHONPATH"); e && *e) {
    if (!fs::exists(fs::path(e) / "rfem" / (module + ".py"), ec))
      throw std::runtime_error(std::string("RFEM_PYTHONPATH=") + e + ": no rfem/" + module + ".py there");
    return e;
  }
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot locate the rfem program to find its Python package: " + ec.message());
  std::istringstream dirs(RFEM_PYTHON_DIRS);
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (dir.empty()) continue;
    const fs::path p = fs::path(dir).is_absolute() ? fs::path(dir) : exe.parent_path() / dir;
    const fs::path clean = p.lexically_normal();
    if (fs::exists(clean / "rfem" / (module + ".py"), ec)) return clean.string();
    looked += (looked.empty() ? "" : ", ") + clean.string();
  }
  return "";
}

#ifdef RFEM_HAVE_PYTHON
namespace py = pybind11;

// rfem.MODULE.main(args) in the embedded interpreter: its return value or SystemExit's code.
int call_main(const std::string& module, const std::vector<std::string>& args) {
  std::string looked;
  const std::string parent = package_parent(module, looked);
  // python3's own configuration (its environment, UTF-8 under the C locale, Ctrl-C as
  // KeyboardInterrupt), never the current directory on sys.path (an rfem/ there).
  PyConfig config;
  PyConfig_InitPythonConfig(&config);
  config.parse_argv = 0;
  config.safe_path = 1;
  py::scoped_interpreter python(&config, 0, nullptr, false);
  std::string error;
  int code = 0;
  try {
    py::list path = py::module_::import("sys").attr("path");
    if (!parent.empty()) path.insert(0, parent);
    const py::object rc = py::module_::import(("rfem." + module).c_str()).attr("main")(args);
    code = rc.is_none() ? 0 : rc.cast<int>();
  } catch (py::error_already_set& e) {
    if (e.matches(PyExc_SystemExit)) {  // argparse's --help (0) and usage errors (2), sys.exit(…)
      const py::object c = e.value().attr("code");
      if (c.is_none()) code = 0;
      else if (py::isinstance<py::int_>(c)) code = c.cast<int>();
      else error = py::str(c).cast<std::string>();
    } else if (e.matches(PyExc_KeyboardInterrupt)) {
      code = 130;
    } else if (e.matches(PyExc_ModuleNotFoundError) && parent.empty() &&
               py::str(e.value().attr("name")).cast<std::string>().rfind("rfem", 0) == 0) {
      error = "the Python package rfem (rfem/" + module + ".py) is not beside the program (looked in " + looked +
              ") nor installed; set RFEM_PYTHONPATH to the directory that holds rfem/";
    } else {
      error = std::string(py::str(e.type().attr("__name__"))) + ": " + std::string(py::str(e.value()));
    }
  }
  if (!error.empty()) throw std::runtime_error(error);  // (after the Python objects went, before the interpreter)
  return code;
}
#else
int call_main(const std::string& module, const std::vector<std::string>&) {
  std::string looked;
  package_parent(module, looked);  // (the same checks of RFEM_PYTHONPATH)
  print_line("rfem: error: this rfem was built without Python (RFEM_BUILD_PYTHON=OFF or no python3-dev): run the package's "
             "entry point instead, python3 -m rfem." + module);
  return 2;  // (as for an option the program does not know)
}
#endif
}  // namespace

int run_plot(const std::string& results, const std::string& outdir, const std::string& format, bool paper_signs) {
  std::vector<std::string> args{results};
  if (!outdir.empty()) args.insert(args.end(), {"-o", outdir});
  if (!format.empty()) args.insert(args.end(), {"--format", format});
  if (paper_signs) args.push_back("--paper-signs");
  return call_main("plots", args);
}

int run_animate(const std::vector<std::string>& args) { return call_main("animate", args); }

int run_bode(const std::vector<std::string>& args) { return call_main("linear", args); }

}  // namespace rfem::app
