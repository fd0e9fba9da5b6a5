#include "accuracy.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "../results/writer.hpp"
#include "static_study.hpp"

namespace rfem {

Reported reported_by_run(const Case& cs) {
  check_runnable(cs);
  if (!cs.sim.state.empty())
    throw CaseError(cs.path + ": simulation.state: a run from a saved state keeps its n: no accuracy target");
  if (!cs.has_link()) throw CaseError("--accuracy: the case has no flexible link: a rigid manipulator has no n to choose");
  Reported r;
  int group = 0;
  for (RunName run : runs_of(cs.sim.procedure)) {
    if (run == RunName::Rigid) continue;
    for (const LinkCase& l : cs.links) {
      const std::string series = to_string(run) + "/" + (cs.links.size() > 1 ? l.name + "/" : std::string());
      const double length = l.link.total_length();
      r.add("peak:" + series + "u1", group, kZeroPeak * length);
      r.add("peak:" + series + "u2", group++, kZeroPeak * length);
      r.add("peak:" + series + "theta", group++, kZeroPeak);
    }
  }
  return r;
}

Reported reported_by_modes(int count) {
  Reported r;
  for (int k = 1; k <= count; ++k) r.add("mode:" + std::to_string(k), k);
  return r;
}

Reported reported_by_linearize(int count) {
  Reported r;
  for (int k = 1; k <= count; ++k) r.add("linear:" + std::to_string(k), k);
  return r;
}

Reported reported_by_static(const Case& cs, const JointRate& rate) {
  static const char* names[6] = {"ux", "uy", "uz", "rx", "ry", "rz"};
  const StaticStudy s = static_study(cs, kFirstTargetN, rate);
  Reported r;
  for (size_t l = 0; l < s.tips.size(); ++l) {
    const Vec6& m = s.tips[l].motion;
    for (int part = 0; part < 2; ++part) {  // displacements, then rotations: each part one scale
      const double scale = m.segment<3>(3 * part).cwiseAbs().maxCoeff();
      for (int c = 3 * part; c < 3 * part + 3; ++c)
        if (std::abs(m[c]) > 1e-9 * scale)  // (a component zero by symmetry: far below round-off of the rest)
          r.add((s.tips.size() > 1 ? s.tips[l].name + "/" : std::string()) + "tip:" + names[c], static_cast<int>(2 * l) + part);
    }
  }
  return r;
}

const Estimate* AccuracyResult::find(const std::string& quantity) const {
  for (const Estimate& e : estimates)
    if (e.quantity == quantity) return &e;
  return nullptr;
}

AccuracySpec target_of(const Case& cs, const std::vector<std::string>& given, int n, int max_n, double max_time,
                       bool n_starts_ladder) {
  AccuracySpec spec;
  if (max_n > 0 && given.empty() && !cs.accuracy.given())
    throw CaseError("--max-n: applies to a target (--accuracy, or the case's [accuracy])");
  if (max_time != 0.0 && !(max_time > 0.0 && std::isfinite(max_time)))
    throw CaseError("--max-time: must be a positive number of seconds (got " + fmt::format("{}", max_time) + ")");
  if (max_time > 0.0 && given.empty() && !cs.accuracy.given())
    throw CaseError("--max-time: applies to a target (--accuracy, or the case's [accuracy])");
  if (given.empty()) {
    if (!cs.accuracy.given() || n > 0) return spec;
    spec = cs.accuracy;
  } else {
    if (n > 0 && !n_starts_ladder) throw CaseError("--n and --accuracy: give one (the target chooses n)");
    for (const std::string& a : given) add_accuracy(spec, a, "--accuracy");
  }
  if (max_n > 0) spec.max_n = max_n;
  if (max_time > 0.0) spec.max_time = max_time;
  return spec;
}

void apply_target(const Case& cs, const AccuracySpec& target, RefineRequest& rq) {
  if (!target.given()) throw CaseError("accuracy: no target (a relative error, e.g. 1e-3, or QUANTITY=ERROR)");
  if (target.relative > 0.0) check_relative_target(target.relative, "accuracy");
  rq.absolute.assign(rq.quantities.size(), NAN);
  if (rq.groups.empty())
    for (size_t k = 0; k < rq.quantities.size(); ++k) rq.groups.push_back(static_cast<int>(k));
  int next_group = rq.groups.empty() ? 0 : *std::max_element(rq.groups.begin(), rq.groups.end()) + 1;
  for (const AbsoluteTarget& a : target.absolute) {
    try {
      parse_quantity(cs, a.quantity);
    } catch (const CaseError& e) {
      throw CaseError(a.where + ": " + e.what());
    }
    const auto it = std::find(rq.quantities.begin(), rq.quantities.end(), a.quantity);
    if (it != rq.quantities.end()) {
      rq.absolute[static_cast<size_t>(it - rq.quantities.begin())] = a.error;
    } else {
      rq.quantities.push_back(a.quantity);
      rq.groups.push_back(next_group++);
      rq.absolute.push_back(a.error);
    }
  }
  if (target.relative > 0.0) rq.accuracy = target.relative;
  else rq.accuracy.reset();
  rq.max_n = target.max_n > 0 ? target.max_n : kMaxTargetN;
  rq.max_time = target.max_time;
}

AccuracyResult meet_accuracy(const Case& cs, const AccuracySpec& target, const Reported& reported, RefineRequest rq) {
  rq.ns.clear();
  rq.modes.clear();
  rq.quantities = reported.quantities;
  rq.groups = reported.groups;
  apply_target(cs, target, rq);
  rq.zero_below = reported.zero_below;
  rq.zero_below.resize(rq.quantities.size(), 0.0);  // (quantities named only by an absolute target)
  rq.integration_check = true;
  AccuracyResult out;
  out.target = target;
  out.refinement = refine(cs, rq);
  const RefineResult& r = out.refinement;
  out.n = r.ns.empty() ? 0 : r.ns.back();
  if (r.dynamic) out.rtol = r.rtol, out.atol = r.atol;
  out.met = r.met;
  out.shortfall = r.shortfall;
  out.calibration = r.calibration;
  for (size_t k = 0; k < r.tables.size(); ++k) {
    const Refinement& t = r.tables[k];
    Estimate e;
    e.quantity = r.quantities[k].text;
    if (!t.rows.empty()) e.value = t.rows.back().value;
    e.error = t.error, e.error_space = t.error_space, e.error_time = t.error_time;
    e.observed_order = t.observed_order();
    e.asymptotic = t.asymptotic;
    if (k < r.allowed.size()) e.allowed = r.allowed[k];
    if (k < r.zero.size()) e.zero = r.zero[k];
    if (!e.zero)
      for (const std::string& w : t.warnings) out.warnings.push_back(e.quantity + ": " + w);
    out.estimates.push_back(e);
  }
  return out;
}

void write_accuracy(const std::string& path, const AccuracyResult& a) {
  ResultsWriter file(path, Reopen{});
  Table t;
  t.cols = 8;
  std::vector<std::string> names;
  for (const Estimate& e : a.estimates) {
    names.push_back(e.quantity);
    t.data.insert(t.data.end(), {e.value, e.error, e.error_space, e.error_time, e.error_reduction, e.observed_order, e.asymptotic ? 1.0 : 0.0, e.allowed});
    ++t.rows;
  }
  file.write_table("accuracy", t, {"value", "error", "error_space", "error_time", "error_reduction", "observed_order", "asymptotic", "allowed"},
                   {"", "", "", "", "", "1", "1", ""},
                   "each reported value (attribute quantities, the row's) with its error bar at n (docs/accuracy.md); "
                   "NaN: no bar; allowed: the bar its target asked for (inf: none)");
  file.write_attribute("accuracy", "quantities", names);
  file.write_attribute("accuracy", "relative", a.target.relative);
  file.write_attribute("accuracy", "n", a.n);
  file.write_attribute("accuracy", "rtol", a.rtol);
  file.write_attribute("accuracy", "atol", a.atol);
  file.write_attribute("accuracy", "met", a.met ? 1.0 : 0.0);
  if (!a.shortfall.empty()) file.write_attribute("accuracy", "shortfall", a.shortfall);
  file.close();
}

Case at_chosen_tolerances(const Case& cs, const AccuracyResult& a) {
  Case c = cs;
  if (std::isfinite(a.rtol)) c.sim.options.rtol = a.rtol, c.sim.options.atol = a.atol;
  return c;
}

}  // namespace rfem
