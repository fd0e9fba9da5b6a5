// `rfem plot` hands the file to rfem_plot.py (matplotlib + h5py from Debian's packages, run by
// /usr/bin/python3: the python3 first on PATH may not see them). The script is found beside the
// program: ../share/rfem/ from its directory, installed (bin/) and in the build tree (apps/).
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "commands.hpp"

namespace rfem::app {

namespace {
std::string plot_script() {
  if (const char* env = std::getenv("RFEM_PLOT_SCRIPT")) return env;
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("cannot locate the rfem program to find its plot script: " + ec.message());
  return (exe.parent_path().parent_path() / "share" / "rfem" / "rfem_plot.py").string();
}
}  // namespace

int run_plot(const std::string& results, const std::string& outdir, const std::string& format, bool paper_signs) {
  const std::string script = plot_script();
  if (!std::filesystem::exists(script))
    throw std::runtime_error("plot script not found: " + script + " (set RFEM_PLOT_SCRIPT to tools/rfem_plot.py)");
  const char* python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::vector<std::string> args{python, script, results};
  if (!outdir.empty()) args.insert(args.end(), {"-o", outdir});
  if (!format.empty()) args.insert(args.end(), {"--format", format});
  if (paper_signs) args.push_back("--paper-signs");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("cannot start the plot script");
  if (pid == 0) {
    execvp(argv[0], argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

}  // namespace rfem::app
