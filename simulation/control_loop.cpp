// A digital controller in the loop (simulation/simulation.hpp: run_controlled): the controller is the
// simulation's sample-and-hold (Simulation::sample_every: the stepper stops at its samples as at a
// digital law's), its output held from its sample (zero-order hold) and recorded in the run's group
// (run/control).
#include <cmath>
#include <deque>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "../core/check.hpp"
#include "simulation.hpp"

namespace rfem {

RunResult run_controlled(const Case& cs, SimulationOptions opts, const Controller& controller, const ControlOptions& c) {
  RFEM_CHECK_ARGUMENT(static_cast<bool>(controller), "no controller");
  const double t_end = cs.sim.options.t_end;
  const double t0 = opts.state ? opts.state->time() : 0.0;
  if (!(c.sample_time > 0) || !std::isfinite(c.sample_time))
    throw std::invalid_argument(fmt::format("sample_time must be a positive number of seconds (got {:.6g})", c.sample_time));
  if (c.sample_time > t_end)
    throw std::invalid_argument(fmt::format("sample_time = {:.6g} s is longer than the run (simulation.t_end = {:.6g} s)",
                                            c.sample_time, t_end));
  if (t_end / c.sample_time > kMaxOutputs)  // (every sample ends a step: 10⁸ steps at the least)
    throw std::invalid_argument(fmt::format("sample_time = {:.3g} s gives {:.3g} samples over simulation.t_end = {:.6g} s "
                                            "(at most {:.0e}): a longer sample time",
                                            c.sample_time, t_end / c.sample_time, t_end, kMaxOutputs));
  if (c.delay < 0) throw std::invalid_argument(fmt::format("delay must be a whole number of samples ≥ 0 (got {})", c.delay));
  if (c.delay > 0 && static_cast<double>(c.delay) * c.sample_time >= t_end - t0)
    throw std::invalid_argument(fmt::format("delay = {} samples ({:.6g} s) is not shorter than the run ({:.6g} s from t = {:.6g} s): "
                                            "the controller would never act",
                                            c.delay, c.delay * c.sample_time, t_end - t0, t0));
  if (cs.sim.options.kind != IntegratorKind::Esdirk)
    throw CaseError(cs.path + ": simulation.integrator: a controller in the loop needs \"esdirk\" (its steps end at the samples)");
  Simulation sim(cs, std::move(opts));
  const Model& md = sim.model();
  const std::vector<std::string> kinds = sim.joint_inputs();
  // The record: per sample, the time and each force-input joint's held torque or reference (NaN:
  // the case's law).
  std::vector<std::string> columns = {"time"}, units = {"s"};
  std::vector<int> recorded;
  for (int j = 0; j < md.m(); ++j)
    if (kinds[j] != "motion") {
      columns.push_back(md.joints[j].name);
      units.push_back(kinds[j] == "feedback" ? "q_ref or N m" : "N m or N");
      recorded.push_back(j);
    }
  Table record{0, static_cast<long>(columns.size()), {}};
  std::vector<double> now(recorded.size(), NAN);
  auto finish = [&](std::optional<RunStatus> s) {
    sim.record_table("control", record, columns, units,
                     "the controller's outputs in effect from each sample time (zero-order hold; NaN: the case's law)");
    return sim.finish(s);
  };
  std::deque<ControlOutput> pending;
  std::string last;                       // the last output that took effect, for a run that fails after it
  std::optional<ControllerError> failure;  // the controller's, ending the run
  // One sample: the controller sees the snapshot at t_k; its output takes effect `delay` samples
  // later and is held (the simulation's held values) until the next one does.
  const auto at_sample = [&](double tk) {
    try {
      ControlOutput u = controller(tk, sim.snapshot());
      const auto refused = [&](const std::string& why) {
        return ControllerError(ControllerError::Kind::NotFinite, tk, fmt::format("controller: {} at t = {:.6g} s", why, tk));
      };
      for (const auto& [name, tau] : u.torques)
        if (!std::isfinite(tau)) throw refused(fmt::format("joint '{}': torque {} is not finite", name, tau));
      for (const auto& [name, r] : u.references)
        if (!std::isfinite(r.q) || !std::isfinite(r.v) || !std::isfinite(r.tau_ff))
          throw refused("joint '" + name + "': the reference is not finite");
      pending.push_back(std::move(u));
      if (pending.size() > static_cast<size_t>(c.delay)) {
        const ControlOutput& out = pending.front();
        for (const auto& [name, tau] : out.torques) sim.set_torque(name, tau);
        for (const auto& [name, r] : out.references) sim.set_reference(name, r.q, r.v, r.tau_ff);
        last = fmt::format("t = {:.6g} s:", tk);
        for (const auto& [name, tau] : out.torques) last += fmt::format(" {} = {:.6g}", name, tau);
        for (const auto& [name, r] : out.references) last += fmt::format(" {} = {:.6g} (reference)", name, r.q);
        for (size_t i = 0; i < recorded.size(); ++i) {
          const std::string& name = md.joints[recorded[i]].name;
          if (const auto it = out.torques.find(name); it != out.torques.end()) now[i] = it->second;
          if (const auto it = out.references.find(name); it != out.references.end()) now[i] = it->second.q;
        }
        pending.pop_front();
      }
    } catch (const std::exception& e) {
      const auto* typed = dynamic_cast<const ControllerError*>(&e);
      failure = typed ? *typed
                      : ControllerError(ControllerError::Kind::Threw, tk, fmt::format("controller: {} at t = {:.6g} s", e.what(), tk));
      if (c.on_error) {
        try {
          c.on_error(*failure);
        } catch (...) {  // (the caller's channel: the run's record says why in any case)
        }
      }
      throw *failure;  // (ends the run with these words)
    }
    record.data.push_back(tk);
    record.data.insert(record.data.end(), now.begin(), now.end());
    ++record.rows;
  };
  // The samples t_k = k·sample_time from the start's time on: one at the start is taken here, the
  // later ones where the steps reach them (Simulation::sample_every: the stepper's sample-and-hold,
  // as a digital law's); a state's time between two samples goes to the next one under the state's
  // held values first.
  const long k0 = static_cast<long>(std::ceil(t0 / c.sample_time * (1 - 1e-12)));
  long first = k0;
  if (!(k0 * c.sample_time > t0) && k0 * c.sample_time < t_end * (1 - 1e-12) && sim.status().kind == RunStatus::Kind::Running) {
    try {
      at_sample(k0 * c.sample_time);
    } catch (const ControllerError& e) {
      return finish(RunStatus::failed(e.what()));
    }
    first = k0 + 1;
  }
  if (sim.status().kind == RunStatus::Kind::Running) {
    sim.sample_every(c.sample_time, first, at_sample);
    const RunStatus st = sim.advance(t_end);
    // A run that fails under the controller's output says which output it was under.
    if (st.kind == RunStatus::Kind::Failed && !failure && !last.empty())
      return finish(RunStatus::failed(st.reason + " (under the controller's output of " + last + ")"));
  }
  return finish(std::nullopt);
}

}  // namespace rfem
