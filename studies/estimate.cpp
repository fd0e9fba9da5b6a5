#include "estimate.hpp"

#include <fmt/core.h>

#include <cmath>
#include <cstdio>

namespace rfem {

double available_memory() {
  std::FILE* f = std::fopen("/proc/meminfo", "r");
  if (!f) return INFINITY;
  char line[256];
  double kb = INFINITY;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "MemAvailable: %lf kB", &kb) == 1) break;
  std::fclose(f);
  return kb * 1024.0;
}

RunEstimate check_affordable(const Case& cs, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs,
                             int threads, bool time) {
  IntegratorOptions o = cs.sim.options;
  o.parallel.threads = threads;
  const RunEstimate e0 = estimate_run(model, inputs, o, false);
  const double avail = available_memory();
  if (e0.bytes > avail)
    throw CaseError(fmt::format("{}: link.n: a run with n = {} rfes needs about {:.2g} GB of memory, {:.2g} GB are available",
                                cs.path, model->n(), e0.bytes / 1e9, avail / 1e9));
  return time ? estimate_run(model, inputs, o, true) : e0;
}

}  // namespace rfem
