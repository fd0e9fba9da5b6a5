#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include "apps/commands.hpp"

namespace rfem::app {

// `rfem plot` hands the file to tools/rfem_plot.py (matplotlib + h5py from Debian's packages, run
// by /usr/bin/python3: the python3 first on PATH may not see them).
int run_plot(const std::string& results, const std::string& outdir) {
  std::string script = std::string(RFEM_SOURCE_DIR) + "/tools/rfem_plot.py";
  if (!std::filesystem::exists(script)) throw std::runtime_error("plot script not found: " + script);
  const char* python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  std::vector<std::string> args{python, script, results};
  if (!outdir.empty()) args.insert(args.end(), {"-o", outdir});
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
