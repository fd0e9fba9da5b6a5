// `rfem plot` and `rfem animate` run the Python package's modules rfem.plots and rfem.animate
// (matplotlib + h5py from Debian's packages, by /usr/bin/python3: the python3 first on PATH may not
// see them): /usr/bin/python3 -m rfem.plots ARGS, with PYTHONPATH prepended by the directory that
// holds the package. It is found relative to the program — installed, bin/../lib/python3.X/
// dist-packages; in the build tree, apps/../python (RFEM_PYTHON_DIRS, from python/CMakeLists.txt)
// — or given by $RFEM_PYTHONPATH.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "commands.hpp"

#ifndef RFEM_PYTHON_DIRS  // ':'-separated, relative to the program's directory (or absolute)
#define RFEM_PYTHON_DIRS "../python"
#endif

namespace rfem::app {

namespace {
namespace fs = std::filesystem;

const char* python() { return fs::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3"; }

// Whether Python finds rfem.MODULE on its own path (an installed package; -P: not in the current
// directory, as the module runs with PYTHONSAFEPATH).
bool python_finds(const std::string& module) {
  const std::string cmd = std::string(python()) + " -P -c 'import importlib.util, sys; sys.exit(importlib.util.find_spec(\"rfem." +
                          module + "\") is None)' >/dev/null 2>&1";
  return std::system(cmd.c_str()) == 0;
}

// The directory holding the package rfem (with rfem/MODULE.py): $RFEM_PYTHONPATH, or the first of
// RFEM_PYTHON_DIRS beside the program that has it, or "" when there is none but Python finds an
// installed one (a build without the module, e.g. the sanitizer build, after an install).
std::string package_parent(const std::string& module) {
  std::error_code ec;
  if (const char* e = std::getenv("RFEM_PYTHONPATH"); e && *e) {
    if (!fs::exists(fs::path(e) / "rfem" / (module + ".py"), ec))
      throw std::runtime_error(std::string("RFEM_PYTHONPATH=") + e + ": no rfem/" + module + ".py there");
    return e;
  }
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot locate the rfem program to find its Python package: " + ec.message());
  std::string looked;
  std::istringstream dirs(RFEM_PYTHON_DIRS);
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (dir.empty()) continue;
    const fs::path p = fs::path(dir).is_absolute() ? fs::path(dir) : exe.parent_path() / dir;
    const fs::path clean = p.lexically_normal();
    if (fs::exists(clean / "rfem" / (module + ".py"), ec)) return clean.string();
    looked += (looked.empty() ? "" : ", ") + clean.string();
  }
  if (python_finds(module)) return "";
  throw std::runtime_error("the Python package rfem (rfem/" + module + ".py) is not beside the program (looked in " +
                           looked + "); set RFEM_PYTHONPATH to the directory that holds rfem/");
}

// Runs /usr/bin/python3 -m rfem.MODULE ARGS with the package on PYTHONPATH; its exit code.
int run_module(const std::string& module, const std::vector<std::string>& module_args) {
  const std::string parent = package_parent(module);
  std::vector<std::string> args{python(), "-m", "rfem." + module};
  args.insert(args.end(), module_args.begin(), module_args.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const char* old = std::getenv("PYTHONPATH");
  const std::string path = parent.empty() ? std::string(old ? old : "") : parent + (old && *old ? ":" + std::string(old) : "");
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start python3 -m rfem." + module);
  if (pid == 0) {
    if (!path.empty()) setenv("PYTHONPATH", path.c_str(), 1);
    setenv("PYTHONSAFEPATH", "1", 1);  // not the current directory first on sys.path (an rfem/ there)
    execvp(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}
}  // namespace

int run_plot(const std::string& results, const std::string& outdir, const std::string& format, bool paper_signs) {
  std::vector<std::string> args{results};
  if (!outdir.empty()) args.insert(args.end(), {"-o", outdir});
  if (!format.empty()) args.insert(args.end(), {"--format", format});
  if (paper_signs) args.push_back("--paper-signs");
  return run_module("plots", args);
}

int run_animate(const std::vector<std::string>& args) { return run_module("animate", args); }

int run_bode(const std::vector<std::string>& args) { return run_module("linear", args); }

}  // namespace rfem::app
