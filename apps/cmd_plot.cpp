// `rfem plot` and `rfem animate` hand the file to rfem_plot.py and rfem_animate.py (matplotlib + h5py
// from Debian's packages, run by /usr/bin/python3: the python3 first on PATH may not see them). The
// scripts are found beside the program: ../share/rfem/ from its directory, installed (bin/) and in
// the build tree (apps/).
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "commands.hpp"

namespace rfem::app {

namespace {
std::string script_path(const std::string& name, const char* env) {
  if (const char* e = std::getenv(env)) return e;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot locate the rfem program to find " + name + ": " + ec.message());
  return (exe.parent_path().parent_path() / "share" / "rfem" / name).string();
}

// Runs tools/NAME (found beside the program, or at $ENV) with /usr/bin/python3; its exit code.
int run_script(const std::string& name, const char* env, const std::vector<std::string>& script_args) {
  const std::string script = script_path(name, env);
  if (!std::filesystem::exists(script))
    throw std::runtime_error("script not found: " + script + " (set " + env + " to tools/" + name + ")");
  const char* python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::vector<std::string> args{python, script};
  args.insert(args.end(), script_args.begin(), script_args.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start " + name);
  if (pid == 0) {
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
  return run_script("rfem_plot.py", "RFEM_PLOT_SCRIPT", args);
}

int run_animate(const std::vector<std::string>& args) { return run_script("rfem_animate.py", "RFEM_ANIMATE_SCRIPT", args); }

}  // namespace rfem::app
