#include "modes_study.hpp"

#include <fmt/core.h>

#include <cmath>

#include "../simulation/validity.hpp"
#include "../solvers/beam_theory.hpp"

namespace rfem {

double ModesStudy::frequency_hz(int i) const { return modes.omega[i] / (2 * M_PI); }

namespace {

// Exact cantilever values apply to one uniform segment without payloads on a held, non-rotating
// base without gravity.
bool has_exact_reference(const Case& cs, const Model& model, const VecX& vb, bool held) {
  if (!held || cs.links.size() != 1 || model.carrying > 0) return false;
  const FlexibleLink& l = cs.links[0].link;
  return l.segments.size() == 1 && l.payloads.empty() && cs.gravity == 0.0 && (vb.size() == 0 || vb.norm() == 0.0) &&
         l.segments[0].section.offset.norm() == 0.0;
}

}  // namespace

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

ModesStudy modes_study(const Case& cs, const ModesRequest& rq) {
  ModesStudy s;
  s.model = model_of(cs, rq.n);
  const Model& model = *s.model;
  if (model.n() == 0) throw CaseError(cs.path + ": link: modal analysis needs a flexible link");
  if (rq.count < 1) throw CaseError(cs.path + ": --count: must be at least 1");
  VecX qb;
  joint_state(cs, rq.rate, qb, s.rates);
  s.free = free_joints(cs, model, rq.free);
  for (int j : s.free) s.free_names.push_back(model.joints[j].name);
  const int nf = static_cast<int>(s.free.size()), all = model.flexible_dofs() + nf;
  s.requested = rq.count;
  s.count = std::min(rq.count, all);
  try {
    s.modes = compute_modes(model, qb, s.rates, s.count, kDenseModesLimit, s.free);
  } catch (const std::invalid_argument& e) {
    throw CaseError(cs.path + ": --free: " + e.what());
  }
  for (int i = 0; i < s.count; ++i)
    if (!std::isfinite(s.modes.omega[i]))
      throw std::runtime_error("mode " + std::to_string(i + 1) + " has no finite frequency: check the case's values");
  s.has_reference = has_exact_reference(cs, model, s.rates, s.free.empty());
  int seen[5] = {0, 0, 0, 0, 0};
  for (int i = 0; i < s.count; ++i) {
    const ModeKind kind = s.modes.kind[i];
    const int k = ++seen[static_cast<int>(kind)];
    s.index_of_kind.push_back(k);
    if (!s.has_reference) continue;
    // The theory the discretisation converges to: Timoshenko for bending (shear and rotary inertia
    // are in the rfes and sdes), rod theory for axial and torsion modes.
    const Segment& sg = cs.links[0].link.segments[0];
    const bool bending = kind == ModeKind::BendingY || kind == ModeKind::BendingZ;
    ModeReference ref;
    ref.reference_hz = (bending ? beam::cantilever_omega_timoshenko(sg, kind, k) : beam::cantilever_omega(sg, kind, k)) / (2 * M_PI);
    ref.theory = bending ? "Timoshenko" : "rod";
    ref.relative_error = (s.frequency_hz(i) - ref.reference_hz) / ref.reference_hz;
    if (bending) ref.euler_bernoulli_hz = beam::cantilever_omega(sg, kind, k) / (2 * M_PI);
    if (!(ref.reference_hz > 0.0) || !std::isfinite(ref.reference_hz) || !std::isfinite(ref.relative_error))
      throw std::runtime_error(fmt::format("mode {}: {:g} Hz against a reference of {:g} Hz: the case's values are out of "
                                           "range (check the units of E, G, rho and the section)",
                                           i + 1, s.frequency_hz(i), ref.reference_hz));
    s.reference.push_back(ref);
  }
  {  // modes about a state that is not small linearise about something the model does not describe
    ValidityMonitor validity(model);
    validity.check(s.modes.q0, NAN);
    for (const auto& w : validity.warnings("the equilibrium the modes are about")) s.warnings.push_back(w);
  }
  for (int i = 0; i < s.count; ++i)
    if (s.modes.uncertainty[i] > kUncertaintyTolerance)
      s.warnings.push_back(fmt::format("mode {}: two eigen-solutions with different shifts differ by {:.1e} of omega^2 "
                                       "(> {:.0e}): round-off of the stiff sdes at n = {}; fewer rfes give more accurate frequencies",
                                       i + 1, s.modes.uncertainty[i], kUncertaintyTolerance, model.n()));
  return s;
}

void write_modes(ResultsWriter& file, const ModesStudy& s) {
  const Model& M = *s.model;
  const int count = s.count, N = static_cast<int>(s.modes.shapes.rows());
  // Column names of the coordinates in the model's order, then the free joints'.
  std::vector<std::string> names(M.dof()), units(M.dof());
  static const char* axis[6] = {"x1", "x2", "x3", "phi1", "phi2", "phi3"};
  for (size_t l = 0; l < M.links.size(); ++l)
    for (int k = 0; k < M.links[l].n(); ++k)
      for (int a = 0; a < 6; ++a) {
        names[M.rfe_index(static_cast<int>(l), k) + a] = fmt::format("{}.rfe{}.{}", M.links[l].name, k + 1, axis[a]);
        units[M.rfe_index(static_cast<int>(l), k) + a] = a < 3 ? "m" : "rad";
      }
  for (int j = 0; j < M.m(); ++j) {
    names[M.joint_index(j)] = M.joints[j].name;
    units[M.joint_index(j)] = M.joints[j].type == JointType::Revolute ? "rad" : "m";
  }
  std::vector<std::string> cols(names.begin(), names.begin() + M.flexible_dofs()),
      col_units(units.begin(), units.begin() + M.flexible_dofs());
  for (int j : s.free) {
    cols.push_back(names[M.joint_index(j)]);
    col_units.push_back(units[M.joint_index(j)]);
  }
  Table shapes{count, N, std::vector<double>(static_cast<size_t>(count) * N)}, f{count, 1, {}}, w{count, 1, {}};
  for (int i = 0; i < count; ++i) {
    for (int r = 0; r < N; ++r) shapes.data[static_cast<size_t>(i) * N + r] = s.modes.shapes(r, i);
    f.data.push_back(s.frequency_hz(i));
    w.data.push_back(s.modes.omega[i]);
  }
  file.write_table("modes/frequency", f, {"f"}, {"Hz"}, "natural frequency of each mode (row)");
  file.write_table("modes/omega", w, {"omega"}, {"rad/s"}, "natural circular frequency of each mode (row)");
  file.write_table("modes/shapes", shapes, cols, col_units,
                   "mode shapes, a row per mode: rfe coordinates (displacements from the equilibrium) and free joints, "
                   "M-normalised");
  const Table q0{1, M.dof(), std::vector<double>(s.modes.q0.data(), s.modes.q0.data() + s.modes.q0.size())};
  file.write_table("modes/equilibrium", q0, names, units, "every coordinate of the state the modes are about");
  for (const MountedLink& L : M.links) {
    Table c{L.n(), 3, {}};
    for (const Rfe& r : L.d.rfes) c.data.insert(c.data.end(), {r.centre[0], r.centre[1], r.centre[2]});
    file.write_table("links/" + L.name + "/rfe_centre", c, {"x", "y", "z"}, {"m", "m", "m"},
                     "undeformed mass centre of rfe k (row k-1) in {r}");
  }
  std::vector<std::string> kinds;
  for (int i = 0; i < count; ++i) kinds.push_back(to_string(s.modes.kind[i]) + std::to_string(s.index_of_kind[i]));
  file.write_attribute("modes", "kinds", kinds);
  file.write_attribute("modes", "free_joints", s.free_names.empty() ? std::vector<std::string>{"(none)"} : s.free_names);
}

}  // namespace rfem
