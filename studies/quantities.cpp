#include "rfem/studies/quantities.hpp"

#include <fmt/core.h>

#include <cctype>
#include <cmath>

#include "rfem/core/positions.hpp"
#include "rfem/solvers/modes.hpp"
#include "rfem/solvers/statics.hpp"

namespace rfem {

namespace {

// "A/B/Q": the prefixes A, B and the quantity Q. A prefix that names a link of the case sets
// `link`; any other is the run (`run`, empty if none). Throws for more prefixes than that.
std::string split_prefixes(const Case& cs, const std::string& quantity, std::string& run, int& link) {
  std::string q = quantity;
  run.clear();
  link = -1;
  for (auto slash = q.find('/'); slash != std::string::npos; slash = q.find('/')) {
    const std::string p = q.substr(0, slash);
    q = q.substr(slash + 1);
    const int l = cs.link_index(p);
    if (l >= 0 && link < 0) link = l;
    else if (l < 0 && run.empty() && link < 0) run = p;
    else throw CaseError("--quantity " + quantity + ": expected [RUN/][LINK/]QUANTITY ('" + p + "' is not where a run or link goes)");
  }
  return q;
}

void parse_static(const Case& cs, const std::string& text, Quantity& s) {
  std::string run;
  const std::string quantity = split_prefixes(cs, text, run, s.link);
  if (!run.empty()) throw CaseError("--quantity " + text + ": no link named '" + run + "'");
  if (s.link >= 0 && quantity.rfind("tip:", 0) != 0) throw CaseError("--quantity " + text + ": only tip quantities name a link");
  const auto colon = quantity.find(':');
  const std::string what = quantity.substr(0, colon);
  const std::string arg = colon == std::string::npos ? "" : quantity.substr(colon + 1);
  if (what == "tip") {
    static const char* names[6] = {"ux", "uy", "uz", "rx", "ry", "rz"};
    for (int i = 0; i < 6; ++i)
      if (arg == names[i]) {
        s.kind = Quantity::Kind::Tip;
        s.component = i;
        return;
      }
    throw CaseError("--quantity " + quantity + ": tip component must be ux, uy, uz, rx, ry or rz");
  }
  if (what != "mode" && what != "axial" && what != "bending-y" && what != "bending-z" && what != "torsion")
    throw CaseError("--quantity " + quantity + ": unknown quantity '" + what +
                    "' ([LINK/]tip:ux…rz, mode:K, axial:K, bending-y:K, bending-z:K, torsion:K, "
                    "[RUN/][LINK/]peak:u1|u2|theta, [RUN/][LINK/]u1@T, u2@T, theta@T, [RUN/]tauJ@T, qJ@T)");
  size_t used = 0;
  try {
    s.mode = std::stoi(arg, &used);
  } catch (...) {
    used = 0;
  }
  if (used == 0 || used != arg.size() || s.mode < 1)
    throw CaseError("--quantity " + quantity + ": expected " + what + ":K with an integer K ≥ 1");
  s.kind = what == "mode" ? Quantity::Kind::Mode : Quantity::Kind::ModeOfKind;
  s.mode_kind = what;
}

// Returns false if `quantity` is not dynamic; throws CaseError if it is but cannot be evaluated.
bool parse_dynamic(const Case& cs, const std::string& quantity, Quantity& d) {
  const bool paper = cs.sim.procedure == Procedure::Paper;
  const bool prefixed = quantity.find('/') != std::string::npos;
  const std::string q = split_prefixes(cs, quantity, d.run, d.link);
  if (d.run.empty()) d.run = paper ? "kinematic" : "run";
  std::string what;
  if (q.rfind("peak:", 0) == 0) {
    what = q.substr(5);
    d.kind = Quantity::Kind::Peak;
  } else if (const auto at = q.find('@'); at != std::string::npos) {
    what = q.substr(0, at);
    d.kind = Quantity::Kind::AtTime;
    size_t used = 0;
    try {
      d.time = std::stod(q.substr(at + 1), &used);
    } catch (...) {
      used = 0;
    }
    if (used == 0 || used != q.size() - at - 1 || !std::isfinite(d.time))
      throw CaseError("--quantity " + quantity + ": '" + q.substr(at + 1) + "' is not a time");
  } else {
    if (prefixed && q.rfind("tip:", 0) != 0) throw CaseError("--quantity " + quantity + ": expected RUN/peak:X or RUN/X@T");
    return false;
  }
  if (what.rfind("tau", 0) == 0 || (what.size() > 1 && what[0] == 'q' && std::isdigit(static_cast<unsigned char>(what[1])))) {
    const std::string num = what.substr(what[0] == 'q' ? 1 : 3);
    d.joint = num.empty() ? 0 : std::atoi(num.c_str());
    if (d.joint < 1 || d.joint > static_cast<int>(cs.joints.size()))
      throw CaseError("--quantity " + quantity + ": joint must be 1.." + std::to_string(cs.joints.size()));
    d.coordinate = what[0] == 'q';
    if (d.link >= 0) throw CaseError("--quantity " + quantity + ": joint quantities name no link");
  } else if (what != "u1" && what != "u2" && what != "theta") {
    throw CaseError("--quantity " + quantity + ": expected u1, u2, theta, tauJ or qJ");
  } else if (cs.links.empty()) {
    throw CaseError("--quantity " + quantity + ": the case has no flexible link");
  } else {
    d.component = what == "u1" ? 0 : what == "u2" ? 1 : 2;
  }
  if (!cs.has_simulation) throw CaseError(cs.path + ": simulation: a dynamic quantity needs a [simulation] table");
  const bool known = paper ? (d.run == "rigid" || d.run == "kinematic" || d.run == "force") : d.run == "run";
  if (!known) {
    std::string links;
    for (const LinkCase& lc : cs.links) links += (links.empty() ? "" : ", ") + lc.name;
    throw CaseError("--quantity " + quantity + ": no run or link named '" + d.run + "' (" +
                    (paper ? "the paper procedure runs rigid, kinematic and force" : "a single run is named run") +
                    (cs.links.empty() ? std::string() : "; links: " + links) + ")");
  }
  const IntegratorOptions& o = cs.sim.options;
  if (d.time >= 0) {
    const double k = std::round(d.time / o.output_dt);
    const bool on_grid = std::abs(d.time - k * o.output_dt) <= 1e-9 * std::max(1.0, d.time) || d.time == o.t_end;
    if (d.time > o.t_end * (1 + 1e-12) || !on_grid)
      throw CaseError("--quantity " + quantity + ": t = " + fmt::format("{}", d.time) + " s is not an output time (0 … " +
                      fmt::format("{}", o.t_end) + " s every " + fmt::format("{}", o.output_dt) + " s)");
  }
  return true;
}

}  // namespace

Quantity parse_quantity(const Case& cs, const std::string& text) {
  Quantity q;
  q.text = text;
  if (!parse_dynamic(cs, text, q)) {
    q = Quantity{};
    q.text = text;
    parse_static(cs, text, q);
  }
  return q;
}

double evaluate_quantity(const Case& cs, int n, const Quantity& s, const JointRate& rate) {
  if (s.dynamic()) throw std::invalid_argument("evaluate_quantity: " + s.text + " needs a run (a refinement study)");
  const Model model = build_model(cs, n);
  VecX qb, vb;
  joint_state(cs, rate, qb, vb);
  if (s.kind == Quantity::Kind::Tip) {
    if (model.links.empty()) throw CaseError("--quantity " + s.text + ": the case has no flexible link");
    const int l = s.link >= 0 ? s.link : static_cast<int>(model.links.size()) - 1;
    return tip_motion(model, l, solve_static(model, qb, vb, cs.loads).q)[s.component];
  }
  const int k = s.mode;
  if (s.kind == Quantity::Kind::Mode) {
    if (k > model.flexible_dofs())
      throw CaseError("--quantity " + s.text + ": n = " + std::to_string(n) + " has only " + std::to_string(model.flexible_dofs()) + " modes");
    return compute_modes(model, qb, vb, k).omega[k - 1] / (2 * M_PI);
  }
  // Modes of one kind can sit high in the spectrum (axial modes of a slender beam): widen the
  // search until the k-th one appears.
  for (int count = std::min(model.flexible_dofs(), 4 * k + 8);; count = std::min(model.flexible_dofs(), 2 * count)) {
    const ModesResult r = compute_modes(model, qb, vb, count);
    int seen = 0;
    for (int i = 0; i < count; ++i)
      if (to_string(r.kind[i]) == s.mode_kind && ++seen == k) return r.omega[i] / (2 * M_PI);
    if (count == model.flexible_dofs()) break;
  }
  throw std::runtime_error("--quantity " + s.text + ": no such mode among all " + std::to_string(model.flexible_dofs()) +
                           " at n = " + std::to_string(n));
}

double evaluate_quantity(const Case& cs, int n, const std::string& text, const JointRate& rate) {
  return evaluate_quantity(cs, n, parse_quantity(cs, text), rate);
}

double sample_value(const Model& m, const Quantity& d, const OutputSample& s) {
  if (d.joint > 0) return d.coordinate ? s.q[m.joint_index(d.joint - 1)] : s.tau[d.joint - 1];
  return tip_deflection(m, d.link >= 0 ? d.link : static_cast<int>(m.links.size()) - 1, s.q)[d.component];
}

}  // namespace rfem
