#include "refine.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "../simulation/inputs.hpp"

namespace rfem {

namespace {

// One run of the procedure at n — only the runs the quantities read — for every dynamic quantity.
std::vector<double> evaluate_dynamic(const Case& cs, const std::vector<JointInput>& inputs, int n,
                                     const std::vector<Quantity>& qs, const std::string& prefix, const RefineRequest& rq) {
  QuantityRecorder values(qs, prefix);
  RunRequest r;
  r.n = n;
  r.threads = rq.threads;
  r.prefix = prefix;
  r.keep_series = false;
  r.stop = rq.stop;
  r.progress = rq.progress;
  r.observers = rq.observers;
  r.observers.push_back(&values);
  r.warn = rq.warn;
  for (const std::string& name : runs_read(qs)) {
    RunName run;
    if (parse(name, run)) r.runs.push_back(run);
  }
  const auto runs = run_case(cs, model_of(cs, n), inputs, r);
  for (const auto& run : runs)
    if (!run.completed()) {
      if (rq.stop.requested()) return {};
      throw std::runtime_error("n = " + std::to_string(n) + ": " + run.name + " " + run.status.to_string());
    }
  return values.values();
}

// Every quantity at one point of the series (a run of the procedure for the dynamic ones), appended
// to `values`; false (the status interrupted) if the study was stopped. `label` names the point in
// messages ("n = 24", "modes = 8").
bool evaluate_point(const Case& c, int n, const std::vector<JointInput>& inputs, const std::string& prefix,
                    const std::string& label, const RefineRequest& rq, RefineResult& res,
                    std::vector<std::vector<double>>& values) {
  const std::vector<Quantity>& qs = res.quantities;
  std::vector<double> dyn;
  if (res.dynamic) dyn = evaluate_dynamic(c, inputs, n, qs, prefix, rq);
  if (rq.stop.requested()) {
    res.status = RunStatus::interrupted(rq.stop.signal());
    return false;
  }
  for (size_t k = 0; k < qs.size(); ++k) {
    values[k].push_back(qs[k].dynamic() ? dyn[k] : evaluate_quantity(c, n, qs[k], rq.rate));
    if (!std::isfinite(values[k].back()))
      throw std::runtime_error(label + ": " + qs[k].text + " is not finite: check the case's values");
  }
  return true;
}

// Whether every quantity's error bar over the series so far meets the relative target (the time
// part, measured at the end, is not known yet).
bool meets(const std::vector<int>& ns, const std::vector<std::vector<double>>& values, const std::vector<double>& time,
           double target) {
  for (size_t k = 0; k < values.size(); ++k) {
    const Refinement r = assess_refinement(ns, values[k], time[k]);
    if (!r.asymptotic || !(r.error <= target * std::abs(values[k].back()))) return false;
  }
  return true;
}

// Per quantity that misses the target: why, and by how much (the n that would meet it, from the
// observed order, when the bar is there but too wide).
std::vector<std::string> shortfall(const RefineResult& res, const RefineRequest& rq) {
  std::vector<std::string> out;
  for (size_t k = 0; k < res.tables.size(); ++k) {
    const Refinement& t = res.tables[k];
    const double value = t.rows.back().value, want = *rq.accuracy * std::abs(value);
    const std::string q = res.quantities[k].text + " at n = " + std::to_string(res.ns.back()) + ": ";
    if (!t.asymptotic) {
      out.push_back(q + "no error bar (the series is not in the asymptotic range; see the warnings)");
    } else if (std::isfinite(t.error_time) && t.error_time > want) {
      out.push_back(q + fmt::format("the time error {:.3g} alone is above the target {:.3g}: tighten simulation.rtol and atol",
                                    t.error_time, want));
    } else if (!(t.error <= want)) {
      const double p = std::min(t.observed_order(), kTheoreticalOrder);
      const double room = want - (std::isfinite(t.error_time) ? t.error_time : 0.0);
      const double n = res.ns.back() * std::pow(t.error_space / room, 1.0 / p);
      out.push_back(q + fmt::format("the bar {:.3g} is {:.3g} times the target {:.3g}; n ≈ {:.0f} would meet it, above --max-n {}",
                                    t.error, t.error / want, want, std::ceil(n), rq.max_n));
    }
  }
  return out;
}

// The case with every flexible link at n reduced to m modes (0: every rfe coordinate).
Case with_modes(const Case& cs, int n, int m) {
  Case c = cs;
  const Model model = build_model(cs, n);
  for (size_t l = 0; l < c.links.size() && l < model.links.size(); ++l)
    if (model.links[l].n() > 0) {
      c.links[l].modes = m;
      c.links[l].modes_line = 0;
      c.links[l].derivatives = std::min(c.links[l].derivatives, m);  // (of the modes kept)
    }
  return c;
}

// The series over modes: the full model first (the reference), then each m.
RefineResult refine_modes(const Case& cs, const RefineRequest& rq, RefineResult res, const std::vector<JointInput>& inputs) {
  const std::vector<Quantity>& qs = res.quantities;
  const int n = rq.ns[0];
  std::vector<int> ms{0};
  ms.insert(ms.end(), rq.modes.begin(), rq.modes.end());
  std::vector<std::vector<double>> values(qs.size());
  res.status = RunStatus::completed();
  for (size_t i = 0; i < ms.size(); ++i) {
    const int m = ms[i];
    if (rq.on_n) rq.on_n(static_cast<int>(i), static_cast<int>(ms.size()), m);
    if (!evaluate_point(with_modes(cs, n, m), n, inputs, m ? fmt::format("m{}/", m) : std::string("full/"),
                        "modes = " + std::to_string(m), rq, res, values))
      break;
  }
  const size_t done = values.empty() ? 0 : values[0].size();
  if (done > 0) res.ns = {n};
  for (size_t i = 1; i < done; ++i) res.modes.push_back(ms[i]);
  if (done > 0) res.modes.push_back(0);
  for (size_t k = 0; k < qs.size(); ++k) {
    Refinement t;
    t.fitted_order = t.integration_error = NAN;
    for (size_t i = 1; i < done; ++i) t.rows.push_back({ms[i], values[k][i], values[k][i] - values[k][0], NAN, NAN});
    if (done > 0) t.rows.push_back({0, values[k][0], 0.0, NAN, NAN});
    res.tables.push_back(std::move(t));
  }
  return res;
}

}  // namespace

std::vector<Quantity> check_refinement(const Case& cs, const RefineRequest& rq) {
  if (rq.quantities.empty()) throw CaseError("--quantity: give at least one quantity (see rfem refine --help)");
  if (!rq.modes.empty()) {
    if (rq.accuracy) throw CaseError("--accuracy: a target is met over n, not over --modes");
    if (rq.ns.size() != 1) throw CaseError("--n: a series over --modes takes one n (got " + std::to_string(rq.ns.size()) + ")");
    if (rq.ns[0] < 1) throw CaseError("--n: must be a positive integer (got " + std::to_string(rq.ns[0]) + ")");
    for (size_t i = 0; i < rq.modes.size(); ++i) {
      if (rq.modes[i] < 1) throw CaseError("--modes: must be at least 1 (got " + std::to_string(rq.modes[i]) + "; the full model is the series' reference)");
      if (i > 0 && rq.modes[i] <= rq.modes[i - 1])
        throw CaseError("--modes: the values must increase (" + std::to_string(rq.modes[i - 1]) + " then " + std::to_string(rq.modes[i]) + ")");
    }
    if (build_model(cs, rq.ns[0]).n() == 0) throw CaseError("--modes: the case has no flexible link at n = " + std::to_string(rq.ns[0]));
    std::vector<Quantity> qs;
    for (const auto& text : rq.quantities) qs.push_back(parse_quantity(cs, text));
    for (int m : rq.modes) build_model(with_modes(cs, rq.ns[0], m), rq.ns[0]);  // more modes than a link has fails here
    return qs;
  }
  if (rq.accuracy) {
    if (!(*rq.accuracy > 0.0 && *rq.accuracy < 1.0))
      throw CaseError(fmt::format("--accuracy: a relative error between 0 and 1, e.g. 1e-3 (got {})", *rq.accuracy));
    if (rq.max_n < 2) throw CaseError("--max-n: must be at least 2 (got " + std::to_string(rq.max_n) + ")");
    if (!rq.ns.empty() && rq.ns.back() > rq.max_n)
      throw CaseError("--n: " + std::to_string(rq.ns.back()) + " is above --max-n " + std::to_string(rq.max_n));
  } else if (rq.ns.size() < 2) {
    throw CaseError("--n: refine needs at least two values (or --accuracy, which chooses them)");
  }
  for (size_t i = 0; i < rq.ns.size(); ++i) {
    if (rq.ns[i] < 1) throw CaseError("--n: must be a positive integer (got " + std::to_string(rq.ns[i]) + ")");
    if (i > 0 && rq.ns[i] <= rq.ns[i - 1])
      throw CaseError("--n: the values must increase (" + std::to_string(rq.ns[i - 1]) + " then " + std::to_string(rq.ns[i]) + ")");
  }
  std::vector<Quantity> qs;
  for (const auto& text : rq.quantities) qs.push_back(parse_quantity(cs, text));
  for (int n : rq.ns) build_model(cs, n);  // an impossible discretisation fails here
  if (rq.accuracy && rq.ns.empty()) build_model(cs, kFirstTargetN);
  return qs;
}

RefineResult refine(const Case& cs, const RefineRequest& rq) {
  RefineResult res;
  res.quantities = check_refinement(cs, rq);
  const std::vector<Quantity>& qs = res.quantities;
  res.dynamic = std::any_of(qs.begin(), qs.end(), [](const Quantity& q) { return q.dynamic(); });
  const std::vector<JointInput> inputs = res.dynamic ? joint_inputs(cs, rq.warn) : std::vector<JointInput>{};
  if (!rq.modes.empty()) return refine_modes(cs, rq, std::move(res), inputs);
  const Case& study = cs;
  std::vector<std::vector<double>> values(qs.size());
  std::vector<double> integration(qs.size(), 0.0);  // (none in a static or modal value)
  for (size_t k = 0; k < qs.size(); ++k)
    if (qs[k].dynamic()) integration[k] = NAN;  // (not measured, unless checked below)
  const bool targeted = rq.accuracy.has_value();
  std::vector<int> ladder = rq.ns;
  if (targeted && ladder.empty()) ladder.push_back(kFirstTargetN);
  res.status = RunStatus::completed();
  for (size_t i = 0;; ++i) {
    if (i == ladder.size()) {  // a target: three levels at least, then until the bars meet it
      if (!targeted || (ladder.size() >= 3 && meets(res.ns, values, integration, *rq.accuracy))) break;
      if (2 * ladder.back() > rq.max_n) break;
      ladder.push_back(2 * ladder.back());
    }
    const int n = ladder[i];
    if (rq.on_n) rq.on_n(static_cast<int>(i), targeted ? 0 : static_cast<int>(ladder.size()), n);
    if (!evaluate_point(study, n, inputs, fmt::format("n{}/", n), "n = " + std::to_string(n), rq, res, values)) break;
    res.ns.push_back(n);
  }
  // The integration error of the finest run: the same n at tolerances 100 times tighter.
  if (res.dynamic && rq.integration_check && res.status.is_completed()) {
    if (rq.on_n) rq.on_n(static_cast<int>(res.ns.size()), static_cast<int>(res.ns.size()), res.ns.back());
    Case tight = study;
    tight.sim.options.rtol /= 100;
    tight.sim.options.atol /= 100;
    tight.sim.options.max_steps *= 100;
    const auto ref = evaluate_dynamic(tight, inputs, res.ns.back(), qs, fmt::format("check_n{}/", res.ns.back()), rq);
    if (rq.stop.requested()) res.status = RunStatus::interrupted(rq.stop.signal());
    else
      for (size_t k = 0; k < qs.size(); ++k)
        if (qs[k].dynamic()) integration[k] = std::abs(values[k].back() - ref[k]);
  }
  for (size_t k = 0; k < qs.size(); ++k) res.tables.push_back(assess_refinement(res.ns, values[k], integration[k]));
  if (targeted && res.status.is_completed()) res.shortfall = shortfall(res, rq);
  res.met = targeted && res.status.is_completed() && res.shortfall.empty();
  return res;
}

}  // namespace rfem
