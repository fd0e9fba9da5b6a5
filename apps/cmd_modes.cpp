#include <fmt/core.h>
#include <fmt/ranges.h>

#include <cmath>

#include "apps/commands.hpp"
#include "solvers/beam_theory.hpp"
#include "solvers/modes.hpp"

namespace rfem::app {

namespace {
// Exact cantilever values apply to one uniform segment without payloads on a held, non-rotating
// base without gravity.
bool has_exact_reference(const Case& cs, const Model& model, const VecX& vb, bool held) {
  if (!held || cs.links.size() != 1 || model.carrying > 0) return false;
  const FlexibleLink& l = cs.links[0].link;
  return l.segments.size() == 1 && l.payloads.empty() && cs.gravity == 0.0 && (vb.size() == 0 || vb.norm() == 0.0) &&
         l.segments[0].section.offset.norm() == 0.0;
}
// --free entries: joint numbers from 1, joint names, or "base" (the six of a free base).
std::vector<int> free_joints(const Case& cs, const Model& model, const std::vector<std::string>& names) {
  std::vector<int> out;
  for (const std::string& s : names) {
    if (s == "base") {
      if (!model.free_base) throw CaseError(cs.path + ": --free base: the case has no free base ([base] kind = \"free\")");
      for (int j = 0; j < free_base_dofs; ++j) out.push_back(j);
      continue;
    }
    int j = -1;
    for (int i = 0; i < model.m(); ++i)
      if (model.joints[i].name == s) j = i;
    if (j < 0 && !s.empty() && s.find_first_not_of("0123456789") == std::string::npos && s.size() < 9) j = std::stoi(s) - 1;
    if (j < 0 || j >= model.m()) {
      std::string list;
      for (const Joint& jt : model.joints) list += (list.empty() ? "" : ", ") + jt.name;
      throw CaseError(cs.path + ": --free " + s + ": no such joint (1 to " + std::to_string(model.m()) + " or " + list + ")");
    }
    out.push_back(j);
  }
  return out;
}

}  // namespace

int run_modes(const Common& c, const ModesOptions& o) {
  const Case cs = read_checked_case(c);
  const Model model = build_model(cs, c.n);
  if (model.n() == 0) throw CaseError(cs.path + ": link: modal analysis needs a flexible link");
  VecX qb, vb;
  joint_state(cs, o, qb, vb);
  const std::vector<int> freed = free_joints(cs, model, o.free);
  const int nf = static_cast<int>(freed.size()), all = model.flexible_dofs() + nf;
  const int count = std::min(o.count, all);
  if (o.count > count && !c.json)
    fmt::print(stderr, "rfem: note: --count {} capped at 6n{} = {} (every mode of n = {} rfes{})\n", o.count,
               nf ? fmt::format(" + {}", nf) : "", count, model.n(), nf ? fmt::format(" and {} free joints", nf) : "");
  ModesResult r;
  try {
    r = compute_modes(model, qb, vb, count, 600, freed);
  } catch (const std::invalid_argument& e) {
    throw CaseError(cs.path + ": --free: " + e.what());
  }
  const bool exact = has_exact_reference(cs, model, vb, freed.empty());
  int seen[5] = {0, 0, 0, 0, 0};
  std::vector<std::string> freed_names;
  for (int j : freed) freed_names.push_back(model.joints[j].name);
  nlohmann::json modes = nlohmann::json::array();
  // References for one uniform segment: the theory the discretisation converges to (Timoshenko for
  // bending: shear and rotary inertia are in the rfes and sdes; rod theory for axial and torsion
  // modes), and the Euler–Bernoulli value beside it for bending.
  if (!c.json)
    fmt::print("modes of {} with n = {} rfes ({} solver){}{}\n{:>4} {:>14} {:>14} {:>12}{}\n",
               cs.name.empty() ? cs.path : cs.name, model.n(), r.dense ? "dense" : "shift-invert Lanczos",
               nf ? fmt::format(", free joints {}", fmt::join(freed_names, " ")) : "",
               vb.size() && vb.norm() > 0 ? fmt::format(", joint rates {}", fmt::join(vb.data(), vb.data() + vb.size(), " ")) : "",
               "mode", "f [Hz]", "omega [rad/s]", "kind",
               exact ? fmt::format(" {:>16} {:>10} {:>16}", "reference [Hz]", "error", "Euler-Bern. [Hz]") : "");
  for (int i = 0; i < count; ++i) {
    const double f = r.omega[i] / (2 * M_PI);
    const int k = ++seen[static_cast<int>(r.kind[i])];
    nlohmann::json jm = {{"mode", i + 1}, {"frequency_hz", f}, {"omega", r.omega[i]}, {"kind", to_string(r.kind[i])},
                         {"index_of_kind", k}, {"uncertainty", r.uncertainty[i]}};
    std::string extra;
    if (exact) {
      const Segment& sg = cs.links[0].link.segments[0];
      const bool bending = r.kind[i] == ModeKind::BendingY || r.kind[i] == ModeKind::BendingZ;
      const double fr = (bending ? beam::cantilever_omega_timoshenko(sg, r.kind[i], k) : beam::cantilever_omega(sg, r.kind[i], k)) /
                        (2 * M_PI);
      jm["reference_hz"] = fr;
      jm["reference_theory"] = bending ? "Timoshenko" : "rod";
      jm["relative_error"] = (f - fr) / fr;
      std::string eb = "-";
      if (bending) {
        const double fe = beam::cantilever_omega(sg, r.kind[i], k) / (2 * M_PI);
        jm["euler_bernoulli_hz"] = fe;
        eb = fmt::format("{:.6f}", fe);
      }
      extra = fmt::format(" {:>11.6f} {:<4} {:>+9.4f}% {:>16}", fr, bending ? "(T)" : "(rod)", 100.0 * (f - fr) / fr, eb);
    }
    modes.push_back(jm);
    if (!c.json)
      fmt::print("{:>4} {:>14.6f} {:>14.6f} {:>12}{}\n", i + 1, f, r.omega[i],
                 fmt::format("{}{}", to_string(r.kind[i]), k), extra);
  }
  for (int i = 0; i < count; ++i)
    if (r.uncertainty[i] > kUncertaintyTolerance)
      fmt::print(stderr, "rfem: warning: mode {}: two eigen-solutions with different shifts differ by {:.1e} of omega^2 "
                 "(> {:.0e}): round-off of the stiff sdes at n = {}; fewer rfes give more accurate frequencies\n",
                 i + 1, r.uncertainty[i], kUncertaintyTolerance, model.n());
  if (!c.json && exact)
    fmt::print("reference: (T) Timoshenko cantilever (shear and rotary inertia), (rod) rod theory; the error is "
               "the discretisation's and falls as 1/n²\n");
  if (c.json) print_json({{"command", "modes"}, {"case", cs.path}, {"n", model.n()}, {"solver", r.dense ? "dense" : "lanczos"},
                          {"free_joints", freed_names},
                          {"modes", modes}});
  return 0;
}

}  // namespace rfem::app
