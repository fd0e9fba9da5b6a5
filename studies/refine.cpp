#include "refine.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
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
  r.reduction_error = false;  // (a ladder's points: meet_accuracy adds the estimate at its n)
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
    values[k].push_back(qs[k].dynamic() ? dyn[k] : evaluate_quantity(c, n, qs[k], rq.rate, rq.free));
    if (!std::isfinite(values[k].back()))
      throw std::runtime_error(label + ": " + qs[k].text + " is not finite: check the case's values");
  }
  return true;
}

// The largest |last value| of quantity k's group (its own without groups).
double group_scale(const RefineRequest& rq, const std::vector<std::vector<double>>& values, size_t k) {
  double scale = values[k].empty() ? 0.0 : std::abs(values[k].back());
  if (!rq.groups.empty())
    for (size_t j = 0; j < values.size(); ++j)
      if (rq.groups[j] == rq.groups[k] && !values[j].empty()) scale = std::max(scale, std::abs(values[j].back()));
  return scale;
}

// Whether quantity k is zero at every n so far, to round-off of its group's scale or below its
// zero_below (a deflection the case's symmetry keeps at zero): it needs no bar.
bool identically_zero(const RefineRequest& rq, const std::vector<std::vector<double>>& values, size_t k) {
  const double below = std::max(kZeroOfScale * group_scale(rq, values, k), k < rq.zero_below.size() ? rq.zero_below[k] : 0.0);
  for (double v : values[k])
    if (std::abs(v) > below) return false;
  return true;
}

// The bar each quantity must meet, from the values so far: the relative target times the scale
// (the largest |last value| of the quantity's group), or its absolute target, whichever is
// smaller; infinite (no target) for a quantity without one or identically zero.
std::vector<double> allowed_bars(const RefineRequest& rq, const std::vector<std::vector<double>>& values) {
  const size_t m = values.size();
  std::vector<double> out(m, INFINITY);
  for (size_t k = 0; k < m; ++k) {
    if (values[k].empty() || identically_zero(rq, values, k)) continue;
    if (rq.accuracy) out[k] = *rq.accuracy * group_scale(rq, values, k);
    if (!rq.absolute.empty() && std::isfinite(rq.absolute[k])) out[k] = std::min(out[k], rq.absolute[k]);
  }
  return out;
}

// Where a ladder with a target stands: every quantity with a target meets it (Met); every one
// either meets it or has had no bar at the last two levels while its last two changes were already
// below its target — an erratic series (a peak read on the output grid) that more levels do not
// make asymptotic (Stalled: the ladder stops, not met); else it goes on.
enum class LadderState { Met, Stalled, Going };

bool erratic_below(const std::vector<int>& ns, const std::vector<double>& v, double allowed) {
  const size_t m = v.size();
  if (m < 4) return false;
  const std::vector<int> before(ns.begin(), ns.end() - 1);
  const std::vector<double> vb(v.begin(), v.end() - 1);
  return !assess_refinement(before, vb, NAN).asymptotic && std::abs(v[m - 1] - v[m - 2]) <= allowed &&
         std::abs(v[m - 2] - v[m - 3]) <= allowed;
}

LadderState ladder_state(const std::vector<int>& ns, const std::vector<std::vector<double>>& values,
                         const std::vector<double>& time, const RefineRequest& rq) {
  const std::vector<double> allowed = allowed_bars(rq, values);
  bool met = true, stalled = true;
  for (size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(allowed[k])) continue;
    const Refinement r = assess_refinement(ns, values[k], time[k]);
    if (r.asymptotic && r.error <= allowed[k]) continue;
    met = false;
    if (r.asymptotic || !erratic_below(ns, values[k], allowed[k])) stalled = false;
  }
  return met ? LadderState::Met : stalled ? LadderState::Stalled : LadderState::Going;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Per quantity that misses its target: why, and by how much (the n that would meet it, from the
// observed order, when the bar is there but too wide).
std::vector<std::string> shortfall(const RefineResult& res, const RefineRequest& rq) {
  std::vector<std::string> out;
  for (size_t k = 0; k < res.tables.size(); ++k) {
    const Refinement& t = res.tables[k];
    const double want = res.allowed[k];
    if (!std::isfinite(want)) continue;
    const std::string q = res.quantities[k].text + " at n = " + std::to_string(res.ns.back()) + ": ";
    if (!t.asymptotic && erratic_below(res.ns, t.column(&RefinementRow::value), want)) {
      out.push_back(q + fmt::format("no error bar: its last changes ({:.3g}, {:.3g}) are below the target {:.3g} but show no "
                                    "order (an erratic series, e.g. a peak read on the output grid); not certified",
                                    t.rows.back().change, t.rows[t.rows.size() - 2].change, want));
    } else if (!t.asymptotic) {
      out.push_back(q + "no error bar (the series is not in the asymptotic range; see the warnings)" +
                    (res.time_limit.empty() ? std::string() : "; stopped: " + res.time_limit));
    } else if (std::isfinite(t.error_time) && t.error_time > want) {
      out.push_back(q + fmt::format("the time error {:.3g} alone is above the target {:.3g}: tighten simulation.rtol and atol",
                                    t.error_time, want));
    } else if (!(t.error <= want)) {
      const double p = std::min(t.observed_order(), kTheoreticalOrder);
      const double room = want - (std::isfinite(t.error_time) ? t.error_time : 0.0);
      const double n = res.ns.back() * std::pow(t.error_space / room, 1.0 / p);
      const std::string limit = res.time_limit.empty() ? fmt::format("above --max-n {}", rq.max_n) : "stopped: " + res.time_limit;
      out.push_back(q + fmt::format("the bar {:.3g} is {:.3g} times the target {:.3g}; n ≈ {:.0f} would meet it, {}", t.error,
                                    t.error / want, want, std::ceil(n), limit));
    }
  }
  return out;
}

// With a relative target: tightens the study's tolerances (from tolerances_for_target, tenfold each
// time, in at most kTries tries) until the time error at the first n — against a rerun at
// tolerances 100 times tighter — is at most kTimeShare of each quantity's allowed bar: a ladder that
// meets its target ends on a change above about 0.6 of the bar (the level before did not meet it),
// which then stands ten times clear of the time error, as assess_refinement asks. The time error
// depends on the motion far more than on n, which is why the cheapest n measures it. Returns false
// if the study was stopped.
constexpr int kTries = 4;
constexpr double kTimeShare = 0.05;
bool calibrate_tolerances(Case& study, int n0, const std::vector<JointInput>& inputs, const RefineRequest& rq,
                          RefineResult& res) {
  const std::vector<Quantity>& qs = res.quantities;
  for (int attempt = 0;; ++attempt) {
    if (rq.on_n) rq.on_n(-1, 0, n0);
    Case tight = study;
    tight.sim.options = tightened(study.sim.options, 100);
    const auto v = evaluate_dynamic(study, inputs, n0, qs, fmt::format("tolerances{}/", attempt), rq);
    if (rq.stop.requested()) break;
    const auto vt = evaluate_dynamic(tight, inputs, n0, qs, fmt::format("tolerances{}_tight/", attempt), rq);
    if (rq.stop.requested()) break;
    std::vector<std::vector<double>> at_n0(qs.size());
    for (size_t k = 0; k < qs.size(); ++k)
      if (qs[k].dynamic()) at_n0[k].push_back(v[k]);
    const std::vector<double> allowed = allowed_bars(rq, at_n0);
    double worst = 0.0;  // the largest time error as a share of its allowed bar
    for (size_t k = 0; k < qs.size(); ++k)
      if (qs[k].dynamic() && std::isfinite(allowed[k])) worst = std::max(worst, std::abs(v[k] - vt[k]) / allowed[k]);
    res.calibration.push_back(fmt::format("n = {}, rtol {:g}, atol {:g}: time error {:.2g} of the allowed bar{}", n0,
                                          study.sim.options.rtol, study.sim.options.atol, worst,
                                          worst <= kTimeShare ? fmt::format(" (at most {:g}: kept)", kTimeShare) : ""));
    if (worst <= kTimeShare || attempt + 1 == kTries) return true;
    study.sim.options = tightened(study.sim.options, 10);
  }
  res.status = RunStatus::interrupted(rq.stop.signal());
  return false;
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

IntegratorOptions tightened(IntegratorOptions o, double factor) {
  o.rtol /= factor;
  o.atol /= factor;
  o.atol_velocity /= factor;
  o.atol_energy /= factor;
  o.max_steps = static_cast<long>(std::min(1e9, o.max_steps * factor));
  return o;
}

IntegratorOptions tolerances_for_target(IntegratorOptions o, double relative) {
  o.rtol = std::min(1e-5, relative / 1000);
  o.atol = o.rtol / 100;
  o.atol_velocity = std::min(o.atol_velocity, o.rtol * 1000);
  return o;
}

std::vector<Quantity> check_refinement(const Case& cs, const RefineRequest& rq) {
  if (rq.quantities.empty()) throw CaseError("--quantity: give at least one quantity (see rfem refine --help)");
  if (!rq.modes.empty()) {
    if (rq.accuracy || !rq.absolute.empty()) throw CaseError("--accuracy: a target is met over n, not over --modes");
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
  if (!rq.absolute.empty() && rq.absolute.size() != rq.quantities.size())
    throw CaseError(fmt::format("absolute targets: one per quantity (got {} for {})", rq.absolute.size(), rq.quantities.size()));
  if (!rq.groups.empty() && rq.groups.size() != rq.quantities.size())
    throw CaseError(fmt::format("groups: one per quantity (got {} for {})", rq.groups.size(), rq.quantities.size()));
  for (size_t k = 0; k < rq.absolute.size(); ++k)
    if (!(rq.absolute[k] > 0.0) && !std::isnan(rq.absolute[k]))
      throw CaseError(fmt::format("--accuracy {}: an absolute error bar must be positive (got {})", rq.quantities[k], rq.absolute[k]));
  const bool targeted = rq.accuracy || std::any_of(rq.absolute.begin(), rq.absolute.end(), [](double a) { return std::isfinite(a); });
  if (rq.accuracy) check_relative_target(*rq.accuracy, "--accuracy");
  if (targeted) {
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
  if (targeted && rq.ns.empty()) build_model(cs, kFirstTargetN);
  return qs;
}

RefineResult refine(const Case& cs, const RefineRequest& rq) {
  const auto started = std::chrono::steady_clock::now();
  RefineResult res;
  res.quantities = check_refinement(cs, rq);
  const std::vector<Quantity>& qs = res.quantities;
  res.dynamic = std::any_of(qs.begin(), qs.end(), [](const Quantity& q) { return q.dynamic(); });
  const std::vector<JointInput> inputs = res.dynamic ? joint_inputs(cs, rq.warn) : std::vector<JointInput>{};
  if (!rq.modes.empty()) return refine_modes(cs, rq, std::move(res), inputs);
  const bool targeted = rq.accuracy || std::any_of(rq.absolute.begin(), rq.absolute.end(), [](double a) { return std::isfinite(a); });
  Case study = cs;
  std::vector<int> ladder = rq.ns;
  if (targeted && ladder.empty()) ladder.push_back(kFirstTargetN);
  res.status = RunStatus::completed();
  if (res.dynamic && rq.accuracy) {
    study.sim.options = tolerances_for_target(cs.sim.options, *rq.accuracy);
    if (!calibrate_tolerances(study, ladder[0], inputs, rq, res)) return res;
  }
  res.rtol = study.sim.options.rtol;
  res.atol = study.sim.options.atol;
  std::vector<std::vector<double>> values(qs.size());
  std::vector<double> integration(qs.size(), 0.0);  // (none in a static or modal value)
  for (size_t k = 0; k < qs.size(); ++k)
    if (qs[k].dynamic()) integration[k] = NAN;  // (not measured, unless checked below)
  std::vector<double> level_s;  // wall time of each level
  for (size_t i = 0;; ++i) {
    if (i == ladder.size()) {  // a target: three levels at least, then until the bars meet it
      if (!targeted || (ladder.size() >= 3 && ladder_state(res.ns, values, integration, rq) != LadderState::Going)) break;
      if (2 * ladder.back() > rq.max_n) break;
      if (rq.max_time > 0.0) {
        // The next level's cost: the last one's times its growth (at least linear in n). After it
        // come, at that n, the integration check (100× tighter: ~2× a level with ESDIRK5) and the
        // command's own run: 4 levels' cost in all for dynamic values, 2 for static and modal ones.
        const size_t L = level_s.size();
        const double growth = L >= 2 && level_s[L - 2] > 0.0 ? std::max(2.0, level_s[L - 1] / level_s[L - 2]) : 2.0;
        const double end = seconds_since(started) + level_s.back() * growth * (res.dynamic ? 4.0 : 2.0);
        if (end > rq.max_time) {
          res.time_limit = fmt::format("n = {} would end at about {:.3g} s, past --max-time {:g} s", 2 * ladder.back(), end,
                                       rq.max_time);
          break;
        }
      }
      ladder.push_back(2 * ladder.back());
    }
    const int n = ladder[i];
    if (rq.on_n) rq.on_n(static_cast<int>(i), targeted ? 0 : static_cast<int>(ladder.size()), n);
    const auto level_start = std::chrono::steady_clock::now();
    if (!evaluate_point(study, n, inputs, fmt::format("n{}/", n), "n = " + std::to_string(n), rq, res, values)) break;
    level_s.push_back(seconds_since(level_start));
    res.ns.push_back(n);
  }
  // The integration error of the finest run: the same n at tolerances 100 times tighter.
  if (res.dynamic && rq.integration_check && res.status.is_completed()) {
    if (rq.on_n) rq.on_n(static_cast<int>(res.ns.size()), static_cast<int>(res.ns.size()), res.ns.back());
    Case tight = study;
    tight.sim.options = tightened(study.sim.options, 100);
    const auto ref = evaluate_dynamic(tight, inputs, res.ns.back(), qs, fmt::format("check_n{}/", res.ns.back()), rq);
    if (rq.stop.requested()) res.status = RunStatus::interrupted(rq.stop.signal());
    else
      for (size_t k = 0; k < qs.size(); ++k)
        if (qs[k].dynamic()) integration[k] = std::abs(values[k].back() - ref[k]);
  }
  for (size_t k = 0; k < qs.size(); ++k) res.tables.push_back(assess_refinement(res.ns, values[k], integration[k]));
  if (targeted) res.allowed = allowed_bars(rq, values);
  for (size_t k = 0; k < qs.size(); ++k) res.zero.push_back(!values[k].empty() && identically_zero(rq, values, k));
  if (targeted && res.status.is_completed()) res.shortfall = shortfall(res, rq);
  res.met = targeted && res.status.is_completed() && res.shortfall.empty();
  return res;
}

}  // namespace rfem
