// `rfem refine`: a refinement study; every run and the tables into one HDF5 file for dynamic
// quantities. Ctrl-C keeps (and prints) the rows done so far.
#include <fmt/core.h>

#include <cmath>
#include <memory>

#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../studies/refine.hpp"
#include "../studies/run_file.hpp"
#include "commands.hpp"
#include "progress.hpp"
#include "signals.hpp"

namespace rfem::app {

namespace {

void print_modes_tables(const Case& cs, const RefineResult& res) {
  for (size_t k = 0; k < res.quantities.size(); ++k) {
    const Refinement& t = res.tables[k];
    fmt::print("{} over modes at n = {}: {}\n{:>6} {:>20} {:>14} {:>10}\n", cs.name.empty() ? cs.path : cs.name, res.ns.at(0),
               res.quantities[k].text, "modes", "value", "to full", "relative");
    const double full = t.rows.back().value;
    for (const auto& r : t.rows)
      fmt::print("{:>6} {:>20.12e} {:>14.3e} {:>10}\n", r.n ? std::to_string(r.n) : std::string("full"), r.value, r.change,
                 full != 0.0 ? fmt::format("{:.2e}", std::abs(r.change / full)) : std::string("-"));
  }
}

void print_tables(const Case& cs, const RefineResult& res) {
  if (!res.modes.empty()) return print_modes_tables(cs, res);
  auto opt = [](double x, const char* f) { return std::isfinite(x) ? fmt::format(fmt::runtime(f), x) : std::string("-"); };
  for (size_t k = 0; k < res.quantities.size(); ++k) {
    const Refinement& t = res.tables[k];
    fmt::print("refinement of {} for {}\n{:>6} {:>20} {:>14} {:>8} {:>20}\n", cs.name.empty() ? cs.path : cs.name,
               res.quantities[k].text, "n", "value", "change", "order", "Richardson");
    for (const auto& r : t.rows)
      fmt::print("{:>6} {:>20.12e} {:>14} {:>8} {:>20}\n", r.n, r.value, opt(r.change, "{:.3e}"), opt(r.order, "{:.3f}"),
                 opt(r.richardson, "{:.12e}"));
    fmt::print("fitted order (least squares over all changes): {}", opt(t.fitted_order, "{:.3f}"));
    const bool dynamic = res.quantities[k].dynamic();
    if (dynamic && std::isfinite(t.integration_error))
      fmt::print("; integration error at n = {}: {:.3e}", t.rows.back().n, t.integration_error);
    fmt::print("\n");
    if (t.rows.empty()) continue;
    const RefinementRow& last = t.rows.back();
    if (!t.asymptotic) {
      fmt::print("no error bar at n = {}: the series does not show the asymptotic range (see the warnings)\n", last.n);
      continue;
    }
    const std::string time = !dynamic ? "none" : std::isfinite(t.error_time) ? fmt::format("{:.3e}", t.error_time)
                                                                            : "not measured";
    fmt::print("error bar at n = {}: {:.12e} ± {:.3e}{} (space {:.3e}: GCI, Fs = {:.2f}, order {:.3f}; time {})\n", last.n,
               last.value, t.error, last.value != 0.0 ? fmt::format(", relative {:.2e}", t.error / std::abs(last.value)) : "",
               t.error_space, t.safety_factor, t.observed_order(), time);
  }
}

}  // namespace

int run_refine(const Common& c, const RefineOptions& ro, const ModesOptions& o) {
  const Case cs = read_checked_case(c);
  RefineRequest rq;
  rq.ns = ro.ns;
  rq.modes = ro.modes;
  rq.quantities = ro.quantities;
  rq.integration_check = ro.integration_check;
  rq.rate = o.rate;
  // A target: --accuracy, or the case's [accuracy] for a study without a ladder of its own.
  const AccuracySpec target = accuracy_target(cs, c, true);
  const bool targeted = target.given() && (!c.accuracy.empty() || (ro.modes.empty() && ro.ns.size() < 2));
  if (targeted) apply_target(cs, target, rq);
  rq.threads = c.threads;
  rq.warn = print_warning;
  // Every quantity and every n are checked before the first run (and before the file is made).
  const std::vector<Quantity> qs = check_refinement(cs, rq);  // (with any quantity a target added)
  const bool dynamic = std::any_of(qs.begin(), qs.end(), [](const Quantity& q) { return q.dynamic(); });
  std::string path;  // (a study with runs keeps them in a file, by default beside the case's name)
  if (dynamic || !ro.output.empty()) {
    path = ro.output;
    if (path.empty()) {
      const std::string stem = cs.path.substr(cs.path.find_last_of('/') + 1);
      path = stem.substr(0, stem.rfind('.')) + "_refine.h5";
    }
  }
  const bool quiet = c.json || c.quiet;
  // (the full model: the dearest; with a target, at the largest n it may reach)
  if (dynamic) check_run_cost(cs, model_of(cs, targeted ? rq.max_n : ro.ns.back()), joint_inputs(cs), c);
  const SignalStop signals(rq.stop);
  ProgressLine progress(quiet);
  rq.progress = [&](const Progress& p) { progress.show(p); };
  const auto ladder = ladder_lines(target, false);
  rq.on_n = [&](int i, int count, int n) {
    progress.clear();
    if (quiet) return;
    if (!rq.modes.empty()) fmt::print(stderr, "[{}/{}] {}\n", i + 1, count, n ? fmt::format("modes = {}", n) : std::string("full model"));
    else if (count == 0 || i < 0) ladder(i, count, n);
    else if (i < count) fmt::print(stderr, "[{}/{}] n = {}\n", i + 1, count, n);
    else if (targeted) ladder(i, count, n);  // (the tolerances were chosen: the rerun is 100 times tighter than those)
    else fmt::print(stderr, "[check] n = {} at rtol {:g}\n", n, cs.sim.options.rtol / 100);
  };
  const RefineResult res = path.empty() ? refine(cs, rq) : refine_into_file(cs, rq, path, c.command_line);
  progress.clear();
  for (size_t k = 0; k < qs.size(); ++k)  // warnings always reach stderr, with --json and --quiet too
    for (const auto& w : res.tables[k].warnings) print_warning(qs[k].text + ": " + w);
  // A target that was not met is not success (exit 3), after the tables.
  const int code = res.status.kind == RunStatus::Kind::Interrupted ? 128 + std::max(res.status.signal, 2)
                   : targeted && !res.met                            ? 3
                                                                     : 0;
  if (c.json) {
    auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
    nlohmann::json jq = nlohmann::json::array();
    for (size_t k = 0; k < qs.size(); ++k) {
      nlohmann::json rows = nlohmann::json::array();
      for (const auto& r : res.tables[k].rows)
        if (res.modes.empty())
          rows.push_back({{"n", r.n}, {"value", r.value}, {"change", num(r.change)}, {"order", num(r.order)},
                          {"richardson", num(r.richardson)}});
        else
          rows.push_back({{"modes", r.n}, {"value", r.value}, {"change", num(r.change)}});  // (0: the full model)
      jq.push_back({{"quantity", qs[k].text}, {"rows", rows}, {"fitted_order", num(res.tables[k].fitted_order)},
                    {"integration_error", num(res.tables[k].integration_error)}, {"error", num(res.tables[k].error)},
                    {"error_space", num(res.tables[k].error_space)}, {"error_time", num(res.tables[k].error_time)},
                    {"observed_order", num(res.tables[k].observed_order())}, {"asymptotic", res.tables[k].asymptotic},
                    {"warnings", res.tables[k].warnings}});
    }
    nlohmann::json out = {{"command", "refine"}, {"case", cs.path}, {"status", res.status.to_string()}, {"quantities", jq},
                          {"output", path}};
    if (targeted) {
      nlohmann::json allowed = nlohmann::json::array();
      for (double a : res.allowed) allowed.push_back(num(a));
      out.update({{"accuracy", num(rq.accuracy ? *rq.accuracy : NAN)}, {"met", res.met}, {"shortfall", res.shortfall},
                  {"allowed", allowed}, {"rtol", num(res.dynamic ? res.rtol : NAN)},
                  {"atol", num(res.dynamic ? res.atol : NAN)}, {"calibration", res.calibration}});
    }
    print_json(out);
    return code;
  }
  print_tables(cs, res);
  if (targeted && res.status.is_completed()) {
    const std::string what = rq.accuracy ? fmt::format("accuracy {:g}", *rq.accuracy) : std::string("the absolute targets");
    const std::string tol = res.dynamic ? fmt::format(" (rtol {:g}, atol {:g})", res.rtol, res.atol) : std::string();
    if (res.met) fmt::print("{}: met at n = {}{} by every quantity\n", what, res.ns.back(), tol);
    else fmt::print("{}: NOT met{}\n", what, tol);
    for (const auto& line : res.shortfall) fmt::print("  {}\n", line);
  }
  if (!path.empty())
    fmt::print("every run and the table in {}{}\n", path,
               res.status.is_completed() ? "" : " (" + res.status.to_string() + ")");
  return code;
}

}  // namespace rfem::app
