// A command's target (--accuracy, --max-n, or the case's [accuracy]) and its estimates, printed.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "commands.hpp"
#include "progress.hpp"

namespace rfem::app {

AccuracySpec accuracy_target(const Case& cs, const Common& c, bool n_starts_ladder) {
  return target_of(cs, c.accuracy, c.n, c.max_n, c.max_time, n_starts_ladder);
}

std::function<void(int, int, int)> ladder_lines(const AccuracySpec& spec, bool quiet) {
  if (quiet) return {};
  const std::string what = spec.relative > 0 ? fmt::format("{:g}", spec.relative) : std::string("the absolute targets");
  return [what](int i, int count, int n) {
    if (i < 0) fmt::print(stderr, "[tolerances] n = {}: the time error against 100 times tighter\n", n);
    else if (count > 0) fmt::print(stderr, "[check] n = {} at tolerances 100 times tighter\n", n);
    else fmt::print(stderr, "[{}] n = {} (towards accuracy {})\n", i + 1, n, what);
  };
}

namespace {
std::string opt(double x, const char* f) { return std::isfinite(x) ? fmt::format(fmt::runtime(f), x) : std::string("-"); }
}  // namespace

void print_accuracy(const AccuracyResult& a) {
  const AccuracySpec& spec = a.target;
  for (const std::string& w : a.warnings) print_warning(w);
  for (const std::string& line : a.calibration) fmt::print("tolerances: {}\n", line);
  fmt::print("error bars at n = {}{} (docs/accuracy.md: space by the GCI, {})\n", a.n,
             std::isfinite(a.rtol) ? fmt::format(", rtol {:g}, atol {:g}", a.rtol, a.atol) : std::string(),
             std::isfinite(a.rtol) ? "time by a rerun at 100x tighter tolerances" : "no time integration");
  // A reduced model's bars have a third part (studies/reduction_error.hpp).
  const bool reduced = std::any_of(a.estimates.begin(), a.estimates.end(), [](const Estimate& e) { return std::isfinite(e.error_reduction); });
  fmt::print("{:<28} {:>16} {:>11} {:>9} {:>10} {:>10}{} {:>6} {:>10}\n", "quantity", "value", "± error", "relative", "space", "time",
             reduced ? fmt::format(" {:>10}", "reduction") : std::string(), "order", "target");
  for (const Estimate& e : a.estimates)
    fmt::print("{:<28} {:>16.9e} {:>11} {:>9} {:>10} {:>10}{} {:>6} {:>10}{}\n", e.quantity, e.value, opt(e.error, "{:.3e}"),
               e.value != 0.0 ? opt(e.error / std::abs(e.value), "{:.2e}") : std::string("-"), opt(e.error_space, "{:.2e}"),
               opt(e.error_time, "{:.2e}"), reduced ? fmt::format(" {:>10}", opt(e.error_reduction, "{:.2e}")) : std::string(),
               opt(e.observed_order, "{:.2f}"), opt(e.allowed, "{:.2e}"),
               e.zero ? "  zero at every n" : !e.asymptotic ? "  no bar" : e.met() ? "" : "  MISSED");
  const std::string what = spec.relative > 0 ? fmt::format("accuracy {:g}", spec.relative) : std::string("the absolute targets");
  if (a.met) fmt::print("{}: met at n = {} by every value\n", what, a.n);
  else fmt::print("{}: NOT met\n", what);
  for (const auto& line : a.shortfall) fmt::print("  {}\n", line);
}

nlohmann::json accuracy_json(const AccuracyResult& a) {
  const AccuracySpec& spec = a.target;
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json es = nlohmann::json::array();
  for (const Estimate& e : a.estimates)
    es.push_back({{"quantity", e.quantity}, {"value", e.value}, {"error", num(e.error)}, {"error_space", num(e.error_space)},
                  {"error_time", num(e.error_time)}, {"error_reduction", num(e.error_reduction)}, {"observed_order", num(e.observed_order)}, {"asymptotic", e.asymptotic},
                  {"zero", e.zero}, {"allowed", num(e.allowed)}});
  nlohmann::json abs = nlohmann::json::object();
  for (const AbsoluteTarget& t : spec.absolute) abs[t.quantity] = t.error;
  return {{"relative", num(spec.relative > 0 ? spec.relative : NAN)}, {"absolute", abs}, {"n", a.n}, {"rtol", num(a.rtol)},
          {"atol", num(a.atol)}, {"calibration", a.calibration}, {"warnings", a.warnings}, {"met", a.met}, {"shortfall", a.shortfall}, {"estimates", es}};
}

}  // namespace rfem::app
