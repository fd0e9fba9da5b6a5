#include "reduction_error.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "../results/writer.hpp"
#include "../simulation/common.hpp"
#include "../simulation/inputs.hpp"
#include "../solvers/modes.hpp"

namespace rfem {

int companion_n(const Case& cs, const Model& model) {
  const int n = model.n();
  // Enough rotations beside the m kept that the modes left out, whose effect is the error, are there.
  auto enough = [&](const Model& m) {
    for (const MountedLink& l : m.links)
      if (l.d.modes > 0 && kModalAxes * l.d.n() < kCompanionModes * l.d.modes) return false;
    return true;
  };
  for (int nc = std::max(1, (n + kCompanionShare - 1) / kCompanionShare); nc < n; nc = std::max(nc + 1, nc * 5 / 4))
    if (enough(*model_of(cs, nc))) return nc;
  return n;
}

namespace {

// The run named `prefix` + a run's own name among `runs` (nullptr if none or not completed).
const RunResult* named(const std::vector<RunResult>& runs, const std::string& name) {
  for (const RunResult& r : runs)
    if (r.name == name) return r.completed() ? &r : nullptr;
  return nullptr;
}

// The procedure's runs of `runs` (without rq's prefix), the paper's rigid one left out.
std::vector<RunName> flexible_runs(const Case& cs, const std::vector<RunResult>& runs, const std::string& prefix) {
  std::vector<RunName> out;
  for (RunName r : runs_of(cs.sim.procedure))
    if (r != RunName::Rigid && named(runs, prefix + to_string(r))) out.push_back(r);
  return out;
}

}  // namespace

void estimate_reduction_error(const Case& cs, const Model& model, const RunRequest& rq, std::vector<RunResult>& runs) {
  if (!rq.reduction_error || !has_reduced_link(model) || rq.stop.requested()) return;
  if (runs.empty() || !std::all_of(runs.begin(), runs.end(), [](const RunResult& r) { return r.completed(); })) return;
  const std::vector<RunName> which = flexible_runs(cs, runs, rq.prefix);
  if (which.empty()) return;
  const int nc = companion_n(cs, model);
  Case full = cs;
  for (LinkCase& l : full.links) l.modes = 0, l.derivatives = 0;
  RunRequest c;
  c.n = nc;
  c.threads = rq.threads;
  c.stop = rq.stop;
  c.progress = rq.progress;
  c.progress_interval = rq.progress_interval;
  c.keep_series = false;
  c.checkpoint_interval = 0.0;
  c.reduction_error = false;
  c.runs = which;
  c.warn = [](const std::string&) {};  // (the companions' own validity warnings are the run's)
  // A companion that fails leaves the runs as they are, without an estimate, and says why.
  auto companion = [&](const Case& which_case, const char* what) -> std::optional<std::vector<RunResult>> {
    c.prefix = rq.prefix + "reduction check, " + what + ", n = " + std::to_string(nc) + "/";
    std::vector<RunResult> out;
    std::string why;
    try {
      out = run_case(which_case, model_of(which_case, nc), joint_inputs(which_case, c.warn), c);
    } catch (const std::exception& e) {
      why = e.what();
    }
    for (const RunResult& r : out)
      if (why.empty() && !r.completed()) why = r.name + " " + r.status.to_string();
    if (why.empty() && out.size() != which.size()) why = "not every run ran";
    if (why.empty()) return out;
    if (rq.warn && !rq.stop.requested()) rq.warn("no reduction error estimate: the " + std::string(what) + " at n = " + std::to_string(nc) + ": " + why);
    return std::nullopt;
  };
  const auto f = companion(full, "full model");
  if (!f) return;
  const auto g = companion(cs, "reduced model");
  if (!g) return;
  for (size_t k = 0; k < which.size(); ++k) {
    RunResult& run = *std::find_if(runs.begin(), runs.end(), [&](const RunResult& r) { return r.name == rq.prefix + to_string(which[k]); });
    run.reduction_error.clear();
    for (size_t l = 0; l < run.peaks.size() && l < (*f)[k].peaks.size() && l < (*g)[k].peaks.size(); ++l) {
      const LinkPeaks &a = (*g)[k].peaks[l], &b = (*f)[k].peaks[l];
      run.reduction_error.push_back(LinkPeaks{run.peaks[l].name, a.u1 - b.u1, a.u2 - b.u2, a.theta - b.theta});
    }
    run.reduction_n = nc;
    if (!rq.warn) continue;
    for (size_t l = 0; l < run.reduction_error.size(); ++l) {
      const LinkPeaks &e = run.reduction_error[l], &p = run.peaks[l];
      // u1 and u2 share a scale; a peak below kZeroPeak (of the link's length, or in rad) is zero by
      // the case's symmetry, its round-off no error to warn of.
      const double u = std::max(p.u1, p.u2), length = l < model.links.size() ? model.links[l].d.length : 0.0;
      const double worst = std::max({u > kZeroPeak * length ? std::max(std::abs(e.u1), std::abs(e.u2)) / u : 0.0,
                                     p.theta > kZeroPeak ? std::abs(e.theta) / p.theta : 0.0});
      if (worst > rq.reduction_allowed)
        rq.warn(fmt::format("{}{}: the reduction's estimated error is {:.2e} of a peak, {:.1f}x the {:.0e} aimed at "
                            "(full and reduced runs at n = {}): keep more modes ({}.modes) or none",
                            run.name, run.peaks.size() > 1 ? " link " + p.name : std::string(), worst,
                            worst / rq.reduction_allowed, rq.reduction_allowed, nc, l < cs.links.size() ? cs.links[l].key : "link"));
    }
  }
}

void write_reduction_error(ResultsWriter& file, const std::vector<RunResult>& runs) {
  Table t;
  t.cols = 6;
  std::vector<std::string> rows;
  int n = 0;
  for (const RunResult& r : runs)
    for (size_t l = 0; r.reduction_n > 0 && l < r.reduction_error.size(); ++l) {
      const LinkPeaks &p = r.peaks[l], &e = r.reduction_error[l];
      rows.push_back(r.name + "/" + p.name);
      t.data.insert(t.data.end(), {p.u1, p.u2, p.theta, e.u1, e.u2, e.theta});
      ++t.rows;
      n = r.reduction_n;
    }
  if (rows.empty()) return;
  file.write_table("reduction_error", t, {"peak_u1", "peak_u2", "peak_theta", "error_u1", "error_u2", "error_theta"},
                   {"m", "m", "rad", "m", "m", "rad"},
                   "per run and link (attribute rows), the peaks and their reduction error estimated by the full and the "
                   "reduced model at n (attribute n): reduced - full peaks there (docs/accuracy.md)");
  file.write_attribute("reduction_error", "rows", rows);
  file.write_attribute("reduction_error", "n", static_cast<double>(n));
}

void add_reduction_error(AccuracyResult& a, const std::vector<RunResult>& runs) {
  for (const RunResult& r : runs)
    for (size_t l = 0; r.reduction_n > 0 && l < r.reduction_error.size(); ++l) {
      const LinkPeaks& e = r.reduction_error[l];
      const std::string series = r.name + "/" + (r.peaks.size() > 1 ? r.peaks[l].name + "/" : std::string());
      for (const auto& pe : {std::pair{"u1", e.u1}, std::pair{"u2", e.u2}, std::pair{"theta", e.theta}}) {
        const std::string part = pe.first;  // (no structured binding: Clang 14 cannot capture one)
        const double err = pe.second;
        auto it = std::find_if(a.estimates.begin(), a.estimates.end(),
                               [&](const Estimate& x) { return x.quantity == "peak:" + series + part; });
        if (it == a.estimates.end()) continue;
        Estimate& x = *it;
        if (x.zero) continue;  // (zero at every n by symmetry)
        const bool was = x.met();
        x.error_reduction = std::abs(err);
        x.error = (std::isfinite(x.error) ? x.error : 0.0) + x.error_reduction;
        if (was && !x.met()) {
          a.met = false;
          a.shortfall.push_back(fmt::format("{}: the reduction's estimated error {:.3e} (full and reduced runs at n = {}) "
                                            "brings the bar to {:.3e}, {:.1f}x the {:.3e} asked for: keep more modes",
                                            x.quantity, x.error_reduction, r.reduction_n, x.error, x.error / x.allowed, x.allowed));
        }
      }
    }
}

}  // namespace rfem
