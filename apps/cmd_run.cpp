// `rfem run`: the case's [simulation] by its procedure, into an HDF5 file, a summary per run.
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "commands.hpp"
#include "progress.hpp"
#include "signals.hpp"
#include "rfem/studies/inputs.hpp"
#include "rfem/studies/recorders.hpp"

namespace rfem::app {

namespace {

// Prints each run's summary as it ends (after clearing the progress line).
class SummaryPrinter : public RunObserver {
 public:
  SummaryPrinter(ProgressLine& progress, bool quiet) : progress_(progress), quiet_(quiet) {}
  void end(const RunResult& s) override {
    progress_.clear();
    if (quiet_) return;
    const IntegratorStats& st = s.stats;
    fmt::print("{:<10} {}: t = {:.3f} s, {} outputs, wall {:.3f} s; steps {}, residuals {}, factorisations {}, "
               "Newton iterations {} (failures {}), error-test failures {}\n",
               s.name, s.status.to_string(), s.t_reached, s.samples, s.wall_s, st.steps, st.residual_evals,
               st.factorizations, st.newton_iters, st.newton_fails, st.error_test_fails);
    for (const LinkPeaks& pk : s.peaks)
      fmt::print("{:<10} {}peak |u1| = {:.6e} m, |u2| = {:.6e} m, |theta| = {:.6e} rad{}", "",
                 s.peaks.size() > 1 ? "link " + pk.name + ": " : "", pk.u1, pk.u2, pk.theta, s.peaks.size() > 1 ? "\n" : "; ");
    fmt::print("{}energy balance drift {:.3e} J (scale {:.3e} J)\n", s.peaks.size() == 1 ? "" : fmt::format("{:<10} ", ""),
               s.energy_drift, s.energy_scale);
  }

 private:
  ProgressLine& progress_;
  bool quiet_;
};

// -v: every output step with the integrator's step count and last step size.
class VerboseLog : public RunObserver {
 public:
  void begin(const RunInfo& info) override { run_ = info.name; }
  void sample(const OutputSample& x) override {
    spdlog::debug("{}: output t = {:.6g} s, {} steps, last step {:.3g} s", run_, x.t, x.steps, x.last_step);
  }

 private:
  std::string run_;
};

}  // namespace

int run_simulation(const Common& c, const std::string& output) {
  const Case cs = read_checked_case(c);
  if (!cs.has_simulation) throw CaseError(cs.path + ": simulation: missing table (t_end, output_dt, …) for `rfem run`");
  if (cs.joints.empty()) throw CaseError(cs.path + ": joints: `rfem run` needs at least one base joint");
  const auto model = model_of(cs, c.n);
  const std::vector<JointInput> inputs = joint_inputs(cs, print_warning);  // bad inputs fail before any file is written
  const bool quiet = c.json || c.quiet;
  check_run_cost(cs, model, inputs, c);
  RunRequest rq;
  const SignalStop signals(rq.stop);
  ResultsWriter file = create_results(output, describe(cs, c.command_line, to_string(cs.sim.procedure), model->n(), max_threads(c)));
  if (!quiet)
    fmt::print("rfem run {}: n = {} rfes{}, m = {} joints, t_end = {} s, {} thread(s) -> {}\n", cs.path, model->n(),
               model->links.size() > 1 ? fmt::format(" in {} links", model->links.size()) : "", model->m(),
               cs.sim.options.t_end, max_threads(c), output);
  ProgressLine progress(quiet);
  Hdf5Recorder recorder(file);
  SummaryPrinter summary(progress, quiet);
  VerboseLog log;
  rq.threads = c.threads;
  rq.keep_series = false;
  rq.progress = [&](const Progress& p) { progress.show(p); };
  rq.observers = {&recorder, &summary};
  if (c.verbose) rq.observers.push_back(&log);
  rq.warn = print_warning;
  const std::vector<RunResult> runs = run_case(cs, model, inputs, rq);
  file.close();
  const RunResult& last = runs.back();
  // ParaView's view of every run that stored its poses (also of a failed run: what it computed).
  const std::vector<std::string> xdmf = write_views(cs, *model, output, print_warning);
  if (c.json) {
    nlohmann::json js = nlohmann::json::array();
    for (const auto& r : runs) {
      nlohmann::json links = nlohmann::json::array();
      for (const LinkPeaks& p : r.peaks) links.push_back({{"name", p.name}, {"peak_u1", p.u1}, {"peak_u2", p.u2}, {"peak_theta", p.theta}});
      js.push_back({{"name", r.name}, {"status", r.status.to_string()}, {"completed", r.completed()}, {"t_reached", r.t_reached},
                    {"outputs", r.samples}, {"wall_time_s", r.wall_s}, {"steps", r.stats.steps},
                    {"residual_evals", r.stats.residual_evals}, {"factorizations", r.stats.factorizations},
                    {"newton_iters", r.stats.newton_iters}, {"newton_fails", r.stats.newton_fails},
                    {"error_test_fails", r.stats.error_test_fails}, {"links", links}, {"energy_drift", r.energy_drift},
                    {"energy_scale", r.energy_scale}, {"warnings", r.warnings}});
      if (!r.peaks.empty())  // the last link's, as with one link
        js.back().update({{"peak_u1", r.peaks.back().u1}, {"peak_u2", r.peaks.back().u2}, {"peak_theta", r.peaks.back().theta}});
    }
    print_json({{"command", "run"}, {"case", cs.path}, {"n", model->n()}, {"output", output}, {"xdmf", xdmf}, {"runs", js}});
  } else if (!quiet) {
    fmt::print("results in {}\n", output);
    for (const std::string& x : xdmf) fmt::print("ParaView: {}\n", x);
  }
  if (last.completed()) return 0;
  if (last.status.kind == RunStatus::Kind::Interrupted) return 128 + (last.status.signal > 0 ? last.status.signal : 2);
  fmt::print(stderr, "rfem: error: {}: {}; every completed output step is in {}\n", last.name, last.status.to_string(), output);
  return 1;
}

}  // namespace rfem::app
