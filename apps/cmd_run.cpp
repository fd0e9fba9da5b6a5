#include <fmt/core.h>
#include <omp.h>

#include "apps/simulate.hpp"

namespace rfem::app {

int run_simulation(const Common& c, const std::string& output) {
  const Case cs = read_checked_case(c);
  if (!cs.has_simulation) throw CaseError(cs.path + ": simulation: missing table (t_end, output_dt, …) for `rfem run`");
  if (cs.joints.empty()) throw CaseError(cs.path + ": joints: `rfem run` needs at least one base joint");
  const Model model = build_model(cs, c.n);
  const std::vector<JointInput> inputs = joint_inputs(cs);  // bad inputs fail before any file is written
  check_affordable(cs, model, inputs, c.threads, c.json || c.quiet);
  install_signal_handlers();
  ResultsFile file(output);
  describe_run(file, cs, c, cs.sim.procedure, model.n());
  const bool quiet = c.json || c.quiet;
  if (!quiet)
    fmt::print("rfem run {}: n = {} rfes{}, m = {} joints, t_end = {} s, {} thread(s) -> {}\n", cs.path, model.n(),
               model.links.size() > 1 ? fmt::format(" in {} links", model.links.size()) : "", model.m(),
               cs.sim.options.t_end, omp_get_max_threads(), output);
  const std::vector<RunSummary> runs = simulate_case(cs, model, inputs, file, "", quiet, {}, c.threads);
  const RunSummary& last = runs.back();
  if (c.json) {
    nlohmann::json js = nlohmann::json::array();
    for (const auto& r : runs) {
      nlohmann::json links = nlohmann::json::array();
      for (const LinkPeaks& p : r.peaks) links.push_back({{"name", p.name}, {"peak_u1", p.u1}, {"peak_u2", p.u2}, {"peak_theta", p.theta}});
      js.push_back({{"name", r.name}, {"status", r.status}, {"completed", r.completed}, {"t_reached", r.t_reached},
                    {"outputs", r.samples}, {"wall_time_s", r.wall}, {"steps", r.stats.steps},
                    {"residual_evals", r.stats.residual_evals}, {"factorizations", r.stats.factorizations},
                    {"newton_iters", r.stats.newton_iters}, {"newton_fails", r.stats.newton_fails},
                    {"error_test_fails", r.stats.error_test_fails}, {"links", links}, {"energy_drift", r.energy_drift},
                    {"energy_scale", r.energy_scale}});
      if (!r.peaks.empty())  // the last link's, as with one link
        js.back().update({{"peak_u1", r.peaks.back().u1}, {"peak_u2", r.peaks.back().u2}, {"peak_theta", r.peaks.back().theta}});
    }
    print_json({{"command", "run"}, {"case", cs.path}, {"n", model.n()}, {"output", output}, {"runs", js}});
  } else if (!quiet) {
    fmt::print("results in {}\n", output);
  }
  if (last.completed) return 0;
  if (stop_flag().load()) return 128 + stop_flag().load();
  fmt::print(stderr, "rfem: error: {}: {}; every completed output step is in {}\n", last.name, last.status, output);
  return 1;
}

}  // namespace rfem::app
