#include <fmt/core.h>

#include <cmath>

#include "apps/commands.hpp"
#include "solvers/modes.hpp"
#include "solvers/statics.hpp"

namespace rfem::app {

double evaluate_quantity(const Case& cs, int n, const std::string& quantity, const ModesOptions& o) {
  const Model model = build_model(cs, n);
  VecX qb, vb;
  joint_state(cs, o, qb, vb);
  const auto colon = quantity.find(':');
  const std::string what = quantity.substr(0, colon), arg = colon == std::string::npos ? "" : quantity.substr(colon + 1);
  if (what == "tip") {
    static const char* names[6] = {"ux", "uy", "uz", "rx", "ry", "rz"};
    for (int i = 0; i < 6; ++i)
      if (arg == names[i]) return tip_motion(model, solve_static(model, qb, vb, cs.loads).q)[i];
    throw CaseError("--quantity " + quantity + ": tip component must be ux, uy, uz, rx, ry or rz");
  }
  int k = 0;
  try {
    k = std::stoi(arg);
  } catch (...) {
    k = 0;
  }
  if (k < 1) throw CaseError("--quantity " + quantity + ": expected NAME:K with K ≥ 1");
  if (what != "mode" && what != "axial" && what != "bending-y" && what != "bending-z" && what != "torsion")
    throw CaseError("--quantity " + quantity + ": unknown quantity '" + what + "'");
  if (what == "mode") {
    if (k > 6 * model.n()) throw CaseError("--quantity " + quantity + ": n = " + std::to_string(n) + " has only " + std::to_string(6 * model.n()) + " modes");
    return compute_modes(model, qb, vb, k).omega[k - 1] / (2 * M_PI);
  }
  // Modes of one kind can sit high in the spectrum (axial modes of a slender beam): widen the
  // search until the k-th one appears.
  for (int count = std::min(6 * model.n(), 4 * k + 8);; count = std::min(6 * model.n(), 2 * count)) {
    const ModesResult r = compute_modes(model, qb, vb, count);
    int seen = 0;
    for (int i = 0; i < count; ++i)
      if (to_string(r.kind[i]) == what && ++seen == k) return r.omega[i] / (2 * M_PI);
    if (count == 6 * model.n()) break;
  }
  const int count = 6 * model.n();
  throw std::runtime_error("--quantity " + quantity + ": no such mode among all " + std::to_string(count) +
                           " at n = " + std::to_string(n));
}

int run_refine(const Common& c, const std::vector<int>& ns, const std::string& quantity, const ModesOptions& o) {
  const Case cs = read_case(c.case_path, c.overrides);
  std::vector<double> val(ns.size()), change(ns.size(), NAN), order(ns.size(), NAN), extrap(ns.size(), NAN);
  for (size_t i = 0; i < ns.size(); ++i) {
    val[i] = evaluate_quantity(cs, ns[i], quantity, o);
    if (i >= 1) change[i] = val[i] - val[i - 1];
    // Observed order from three successive values: p = ln(|Δ_{i−1}| / |Δ_i|) / ln(n_i / n_{i−1}).
    if (i >= 2 && change[i] != 0.0 && change[i - 1] != 0.0) {
      order[i] = std::log(std::abs(change[i - 1] / change[i])) / std::log(double(ns[i]) / ns[i - 1]);
      const double r = std::pow(double(ns[i]) / ns[i - 1], order[i]);
      extrap[i] = val[i] + change[i] / (r - 1.0);
    }
  }
  if (c.json) {
    nlohmann::json rows = nlohmann::json::array();
    auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
    for (size_t i = 0; i < ns.size(); ++i)
      rows.push_back({{"n", ns[i]}, {"value", val[i]}, {"change", num(change[i])}, {"order", num(order[i])},
                      {"richardson", num(extrap[i])}});
    print_json({{"command", "refine"}, {"case", cs.path}, {"quantity", quantity}, {"rows", rows}});
    return 0;
  }
  fmt::print("refinement of {} for {}\n{:>6} {:>20} {:>14} {:>8} {:>20}\n", cs.name.empty() ? cs.path : cs.name, quantity,
             "n", "value", "change", "order", "Richardson");
  auto opt = [](double x, const char* f) { return std::isfinite(x) ? fmt::format(fmt::runtime(f), x) : std::string("-"); };
  for (size_t i = 0; i < ns.size(); ++i)
    fmt::print("{:>6} {:>20.12e} {:>14} {:>8} {:>20}\n", ns[i], val[i], opt(change[i], "{:.3e}"), opt(order[i], "{:.3f}"),
               opt(extrap[i], "{:.12e}"));
  return 0;
}

}  // namespace rfem::app
