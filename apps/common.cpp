// Helpers shared by the commands.
#include <fmt/core.h>

#include "commands.hpp"
#include "../assembly/workspace.hpp"
#include "../studies/estimate.hpp"

namespace rfem::app {

void print_json(const nlohmann::json& j) { fmt::print("{}\n", j.dump(2)); }

void print_warning(const std::string& w) { print_line("rfem: warning: " + w); }

void print_line(const std::string& line) noexcept {
  // (stderr gone or full: nothing else to tell, and the exit code still says what happened)
  try {
    fmt::print(stderr, "{}\n", line);
  } catch (...) {
  }
}

Case read_checked_case(const Common& c) {
  Case cs = read_case(c.case_path, c.overrides);
  for (const auto& w : cs.warnings) print_warning(w);
  return cs;
}

void check_run_cost(const Case& cs, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs, const Common& c) {
  const bool note = model->n() >= kLargeRunRfes && !(c.json || c.quiet);
  const RunEstimate e = check_affordable(cs, model, inputs, c.threads, note);
  if (note)
    fmt::print(stderr,
               "rfem: note: n = {} rfes: about {:.0f} MB of memory; one residual evaluation {:.3g} ms, one Newton "
               "matrix {:.3g} ms, so about {:.2g} s per step (the shipped cases take 400 to 6000 steps at the "
               "default tolerances)\n",
               model->n(), e.bytes / 1e6, e.residual_s * 1e3, e.newton_setup_s * 1e3, e.step_s());
}

int max_threads(const Common& c) {
  Parallelism p;
  p.threads = c.threads;
  return p.max_threads();
}

}  // namespace rfem::app
