#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cmath>

#include "apps/commands.hpp"
#include "solvers/beam_theory.hpp"
#include "solvers/modes.hpp"

namespace rfem::app {

namespace {
// Exact cantilever values apply to one uniform segment on a held, non-rotating base without gravity.
bool has_exact_reference(const Case& cs, const VecX& vb) {
  return cs.has_link && cs.link.segments.size() == 1 && cs.gravity == 0.0 && (vb.size() == 0 || vb.norm() == 0.0) &&
         cs.link.segments[0].section.offset.norm() == 0.0;
}
}  // namespace

int run_modes(const Common& c, const ModesOptions& o) {
  const Case cs = read_case(c.case_path, c.overrides);
  const Model model = build_model(cs, c.n);
  if (model.n() == 0) throw CaseError(cs.path + ": link: modal analysis needs a flexible link");
  VecX qb, vb;
  joint_state(cs, o, qb, vb);
  const int count = std::min(o.count, 6 * model.n());
  const ModesResult r = compute_modes(model, qb, vb, count);
  const bool exact = has_exact_reference(cs, vb);
  int seen[4] = {0, 0, 0, 0};
  nlohmann::json modes = nlohmann::json::array();
  if (!c.json)
    fmt::print("modes of {} with n = {} rfes ({} solver){}\n{:>4} {:>14} {:>14} {:>10}{}\n",
               cs.name.empty() ? cs.path : cs.name, model.n(), r.dense ? "dense" : "shift-invert Lanczos",
               vb.size() && vb.norm() > 0 ? fmt::format(", joint rates {}", fmt::join(vb.data(), vb.data() + vb.size(), " ")) : "",
               "mode", "f [Hz]", "omega [rad/s]", "kind", exact ? fmt::format(" {:>14} {:>10}", "exact [Hz]", "error") : "");
  for (int i = 0; i < count; ++i) {
    const double f = r.omega[i] / (2 * M_PI);
    const int k = ++seen[static_cast<int>(r.kind[i])];
    nlohmann::json jm = {{"mode", i + 1}, {"frequency_hz", f}, {"omega", r.omega[i]}, {"kind", to_string(r.kind[i])},
                         {"index_of_kind", k}};
    std::string extra;
    if (exact) {
      const double fe = beam::cantilever_omega(cs.link.segments[0], r.kind[i], k) / (2 * M_PI);
      jm["exact_hz"] = fe;
      jm["relative_error"] = (f - fe) / fe;
      extra = fmt::format(" {:>14.6f} {:>+9.4f}%", fe, 100.0 * (f - fe) / fe);
    }
    modes.push_back(jm);
    if (!c.json)
      fmt::print("{:>4} {:>14.6f} {:>14.6f} {:>10}{}\n", i + 1, f, r.omega[i],
                 fmt::format("{}{}", to_string(r.kind[i]), k), extra);
  }
  if (c.json) print_json({{"command", "modes"}, {"case", cs.path}, {"n", model.n()}, {"solver", r.dense ? "dense" : "lanczos"},
                          {"modes", modes}});
  return 0;
}

}  // namespace rfem::app
