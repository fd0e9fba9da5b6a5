// `rfem run`: the case's [simulation] by its procedure, into an HDF5 file, a summary per run.
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <optional>

#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../studies/reduction_error.hpp"
#include "../studies/resume.hpp"
#include "../studies/run_file.hpp"
#include "commands.hpp"
#include "progress.hpp"
#include "signals.hpp"

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

// What a run and a resumed run show: the progress line, each run's summary, -v's log.
struct Console {
  explicit Console(bool quiet) : progress(quiet), summary(progress, quiet) {}
  Console(const Console&) = delete;
  Console& operator=(const Console&) = delete;
  // The request's threads, checkpoints, progress, observers (after any given) and warnings.
  void attach(RunRequest& rq, const Common& c, const RunOptions& o) {
    rq.threads = c.threads;
    rq.keep_series = false;
    rq.checkpoint_interval = o.checkpoint;
    rq.progress = [this](const Progress& p) { progress.show(p); };
    rq.observers.push_back(&summary);
    if (c.verbose) rq.observers.push_back(&log);
    rq.warn = print_warning;
  }
  ProgressLine progress;
  SummaryPrinter summary;
  VerboseLog log;
};

// The runs' summaries as JSON or text after the runs, and the exit code of the last run.
int report(const std::string& case_path, long n, const std::string& output, const std::vector<RunResult>& runs,
           const std::vector<std::string>& xdmf, const Common& c, bool quiet, const nlohmann::json& accuracy = nullptr) {
  if (c.json) {
    nlohmann::json js = nlohmann::json::array();
    for (const auto& r : runs) {
      nlohmann::json links = nlohmann::json::array();
      for (size_t l = 0; l < r.peaks.size(); ++l) {
        const LinkPeaks& p = r.peaks[l];
        links.push_back({{"name", p.name}, {"peak_u1", p.u1}, {"peak_u2", p.u2}, {"peak_theta", p.theta}});
        if (l < r.reduction_error.size())
          links.back()["reduction_error"] = {{"n", r.reduction_n}, {"u1", r.reduction_error[l].u1},
                                             {"u2", r.reduction_error[l].u2}, {"theta", r.reduction_error[l].theta}};
      }
      js.push_back({{"name", r.name}, {"status", r.status.to_string()}, {"completed", r.completed()}, {"t_reached", r.t_reached},
                    {"outputs", r.samples}, {"wall_time_s", r.wall_s}, {"steps", r.stats.steps},
                    {"residual_evals", r.stats.residual_evals}, {"factorizations", r.stats.factorizations},
                    {"newton_iters", r.stats.newton_iters}, {"newton_fails", r.stats.newton_fails},
                    {"error_test_fails", r.stats.error_test_fails}, {"links", links}, {"energy_drift", r.energy_drift},
                    {"energy_scale", r.energy_scale}, {"warnings", r.warnings}});
      if (!r.peaks.empty())  // the last link's, as with one link
        js.back().update({{"peak_u1", r.peaks.back().u1}, {"peak_u2", r.peaks.back().u2}, {"peak_theta", r.peaks.back().theta}});
    }
    nlohmann::json out = {{"command", "run"}, {"case", case_path}, {"n", n}, {"output", output}, {"xdmf", xdmf}, {"runs", js}};
    if (!accuracy.is_null()) out["accuracy"] = accuracy;
    print_json(out);
  } else if (!quiet) {
    for (const RunResult& r : runs)
      for (const LinkPeaks& e : r.reduction_error)
        fmt::print("{:<10} {}reduction error (estimated: reduced - full peaks at n = {}): u1 {:+.2e} m, u2 {:+.2e} m, theta {:+.2e} rad\n",
                   r.name, r.reduction_error.size() > 1 ? "link " + e.name + ": " : "", r.reduction_n, e.u1, e.u2, e.theta);
    fmt::print("results in {}\n", output);
    for (const std::string& x : xdmf) fmt::print("ParaView: {}\n", x);
  }
  if (runs.empty() || runs.back().completed()) return 0;
  const RunResult& last = runs.back();
  if (last.status.kind == RunStatus::Kind::Interrupted) return 128 + (last.status.signal > 0 ? last.status.signal : 2);
  fmt::print(stderr, "rfem: error: {}: {}; every completed output step is in {}{}\n", last.name, last.status.to_string(), output,
             last.stats.steps > 0 ? fmt::format(" (rfem run --resume {} goes on from its last checkpoint)", output) : "");
  return 1;
}

// `rfem run --resume FILE`: the runs the file has left.
int resume_simulation(const Common& c, const RunOptions& o) {
  const ResumePlan plan = plan_resume(o.resume);
  for (const auto& w : plan.cs.warnings) print_warning(w);
  const bool quiet = c.json || c.quiet;
  if (!quiet) {
    fmt::print("rfem run --resume {}: case {}{}, {} thread(s)\n", o.resume, plan.cs.path,
               plan.n > 0 ? fmt::format(", n = {}", plan.n) : "", max_threads(c));
    for (const std::string& r : plan.done) fmt::print("{:<10} completed before: kept\n", r);
    for (const auto& [r, cp] : plan.resume)
      fmt::print("{:<10} goes on from its checkpoint after output {} ({} outputs kept)\n", r, cp.rows - 1, cp.rows);
    if (plan.finished()) fmt::print("every run had completed: nothing to do\n");
  }
  RunRequest rq;
  rq.reduction_error = !o.no_reduction_check;
  const SignalStop signals(rq.stop);
  Console console(quiet);
  console.attach(rq, c, o);
  const std::vector<RunResult> runs = resume_case(plan, rq);
  std::vector<std::string> xdmf;
  if (!runs.empty()) xdmf = write_views(plan.cs, *runs.back().model, o.resume, print_warning);
  return report(plan.cs.path, runs.empty() ? -1 : runs.back().model->n(), o.resume, runs, xdmf, c, quiet);
}

// A target (--accuracy, [accuracy]): the tolerances and n from a refinement of the peaks the run
// reports (studies/accuracy.hpp); nothing if the caller gives none.
std::optional<AccuracyResult> choose_by_target(const Case& cs, const AccuracySpec& target, const Common& c, RunRequest& rq,
                                               Console& console, bool quiet) {
  if (!target.given()) return std::nullopt;
  const Reported reported = reported_by_run(cs);
  RefineRequest base;
  base.threads = c.threads;
  base.warn = print_warning;
  base.stop = rq.stop;
  base.progress = rq.progress;
  const auto lines = ladder_lines(target, quiet);
  base.on_n = [&](int i, int count, int n) {
    console.progress.clear();
    if (lines) lines(i, count, n);
  };
  AccuracyResult a = meet_accuracy(cs, target, reported, base);
  console.progress.clear();
  rq.n = a.n;
  return a;
}

}  // namespace

int run_simulation(const Common& c, const RunOptions& o) {
  if (!o.resume.empty()) return resume_simulation(c, o);
  const Case given = read_checked_case(c);
  const AccuracySpec target = accuracy_target(given, c);
  const bool quiet = c.json || c.quiet;
  RunRequest rq;
  rq.n = c.n;
  if (target.relative > 0.0) rq.reduction_allowed = target.relative;
  rq.reduction_error = !o.no_reduction_check;
  const SignalStop signals(rq.stop);
  Console console(quiet);
  console.attach(rq, c, o);
  std::optional<AccuracyResult> acc = choose_by_target(given, target, c, rq, console, quiet);
  if (acc && !acc->refinement.status.is_completed()) {  // (stopped by a signal during the ladder)
    fmt::print(stderr, "rfem: the search for n towards the target was {}\n", acc->refinement.status.to_string());
    return 128 + std::max(acc->refinement.status.signal, 2);
  }
  const Case cs = acc ? at_chosen_tolerances(given, *acc) : given;
  const FileRuns f = run_into_file(cs, rq, o.output, c.command_line, [&](const std::shared_ptr<const Model>& mp, const std::vector<JointInput>& inputs) {
    check_run_cost(cs, mp, inputs, c);
    const Model& model = *mp;
    if (!quiet)
      fmt::print("rfem run {}: n = {} rfes{}, m = {} joints, t_end = {} s, {} thread(s){} -> {}\n", cs.path, model.n(),
                 model.links.size() > 1 ? fmt::format(" in {} links", model.links.size()) : "", model.m(),
                 cs.sim.options.t_end, max_threads(c),
                 acc ? fmt::format(", rtol {:g}, atol {:g} (chosen for the target)", cs.sim.options.rtol, cs.sim.options.atol) : "",
                 o.output);
  });
  const bool completed = !f.runs.empty() && f.runs.back().completed();
  if (acc && completed) {
    add_reduction_error(*acc, f.runs);
    write_accuracy(o.output, *acc);
    if (!c.json) print_accuracy(*acc);  // (results: also with -q)
  }
  const int code = report(cs.path, f.model->n(), o.output, f.runs, f.views, c, quiet,
                          acc && completed ? accuracy_json(*acc) : nlohmann::json(nullptr));
  return code == 0 && acc && !acc->met ? 3 : code;  // (a target that was not met is not success)
}

}  // namespace rfem::app
