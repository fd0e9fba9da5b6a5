#include "rfem/studies/refine.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "rfem/studies/inputs.hpp"

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

}  // namespace

std::vector<Quantity> check_refinement(const Case& cs, const RefineRequest& rq) {
  if (rq.quantities.empty()) throw CaseError("--quantity: give at least one quantity (see rfem refine --help)");
  if (rq.ns.size() < 2) throw CaseError("--n: refine needs at least two values");
  for (size_t i = 0; i < rq.ns.size(); ++i) {
    if (rq.ns[i] < 1) throw CaseError("--n: must be a positive integer (got " + std::to_string(rq.ns[i]) + ")");
    if (i > 0 && rq.ns[i] <= rq.ns[i - 1])
      throw CaseError("--n: the values must increase (" + std::to_string(rq.ns[i - 1]) + " then " + std::to_string(rq.ns[i]) + ")");
  }
  std::vector<Quantity> qs;
  for (const auto& text : rq.quantities) qs.push_back(parse_quantity(cs, text));
  for (int n : rq.ns) build_model(cs, n);  // an impossible discretisation fails here
  return qs;
}

RefineResult refine(const Case& cs, const RefineRequest& rq) {
  RefineResult res;
  res.quantities = check_refinement(cs, rq);
  const std::vector<Quantity>& qs = res.quantities;
  res.dynamic = std::any_of(qs.begin(), qs.end(), [](const Quantity& q) { return q.dynamic(); });
  const std::vector<JointInput> inputs = res.dynamic ? joint_inputs(cs, rq.warn) : std::vector<JointInput>{};
  const Case& study = cs;
  std::vector<std::vector<double>> values(qs.size());
  res.status = RunStatus::completed();
  for (size_t i = 0; i < rq.ns.size(); ++i) {
    const int n = rq.ns[i];
    if (rq.on_n) rq.on_n(static_cast<int>(i), static_cast<int>(rq.ns.size()), n);
    std::vector<double> dyn;
    if (res.dynamic) dyn = evaluate_dynamic(study, inputs, n, qs, fmt::format("n{}/", n), rq);
    if (rq.stop.requested()) {
      res.status = RunStatus::interrupted(rq.stop.signal());
      break;
    }
    for (size_t k = 0; k < qs.size(); ++k) {
      values[k].push_back(qs[k].dynamic() ? dyn[k] : evaluate_quantity(cs, n, qs[k], rq.rate));
      if (!std::isfinite(values[k].back()))
        throw std::runtime_error("n = " + std::to_string(n) + ": " + qs[k].text + " is not finite: check the case's values");
    }
    res.ns.push_back(n);
  }
  // The integration error of the finest run: the same n at tolerances 100 times tighter.
  std::vector<double> integration(qs.size(), NAN);
  if (res.dynamic && rq.integration_check && res.status.is_completed()) {
    if (rq.on_n) rq.on_n(static_cast<int>(rq.ns.size()), static_cast<int>(rq.ns.size()), res.ns.back());
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
  return res;
}

}  // namespace rfem
