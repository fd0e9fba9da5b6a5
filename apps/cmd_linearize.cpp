// `rfem linearize`: the case's linear model (M, D, K, B, C and A, B, C, D with their names) about
// its initial equilibrium or a saved state, into HDF5; prints its size and lowest frequencies.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "../results/errors.hpp"
#include "../simulation/recorders.hpp"
#include "../studies/run_file.hpp"
#include "commands.hpp"

namespace rfem::app {

int run_linearize(const Common& c, const LinearizeOptions& o) {
  const Case cs = read_checked_case(c);
  LinearizeRequest rq;
  rq.n = c.n;
  // A target: n from a refinement of the linear model's six lowest frequencies (studies/accuracy.hpp).
  const AccuracySpec target = accuracy_target(cs, c);
  std::optional<AccuracyResult> acc;
  if (target.given()) {
    if (!o.state.empty()) throw CaseError("--accuracy: a saved state has its own n (give no --state, or no target)");
    RefineRequest base;
    base.warn = print_warning;
    base.on_n = ladder_lines(target, c.json || c.quiet);
    acc = meet_accuracy(cs, target, reported_by_linearize(6), base);
    rq.n = acc->n;
  }
  rq.threads = c.threads > 0 ? c.threads : 1;
  rq.equilibrium = !o.on_motion;
  rq.dense = o.dense;
  if (!o.state.empty()) {
    try {
      rq.state = std::make_shared<const SimulationState>(load_state(o.state));
    } catch (const std::exception& e) {
      throw CaseError(std::string("--state: ") + e.what());  // (its message names the file)
    }
  }
  LinearModel lin;
  try {
    lin = linearize_into_file(cs, rq, o.output, c.command_line);
  } catch (const std::invalid_argument& e) {  // another model's state
    throw CaseError("--state: " + o.state + ": " + e.what());
  }
  // The first-order model's eigenvalues: frequencies [Hz] and damping ratios of its lowest modes.
  const std::vector<std::pair<double, double>> modes = linear_modes(lin, 6);
  const int shown = static_cast<int>(modes.size());
  if (acc) write_accuracy(o.output, *acc);
  const int code = acc && !acc->met ? 3 : 0;  // (a target that was not met is not success)
  if (c.json) {
    nlohmann::json f = nlohmann::json::array(), z = nlohmann::json::array();
    for (int i = 0; i < shown; ++i) {
      f.push_back(modes[static_cast<size_t>(i)].first);
      z.push_back(modes[static_cast<size_t>(i)].second);
    }
    print_json({{"command", "linearize"}, {"case", cs.path}, {"output", o.output}, {"t", lin.t},
                {"about", lin.equilibrium ? "equilibrium" : "state"}, {"states", lin.states.size()},
                {"inputs", lin.inputs}, {"outputs", lin.outputs.size()}, {"imbalance", lin.imbalance},
                {"evaluations", lin.evaluations}, {"nonzeros", {{"M", lin.M.nonZeros()}, {"D", lin.D.nonZeros()}, {"K", lin.K.nonZeros()}}},
                {"frequencies_hz", f}, {"damping_ratios", z}, {"accuracy", acc ? accuracy_json(*acc) : nlohmann::json(nullptr)}});
    return code;
  }
  if (c.quiet) {
    if (acc) print_accuracy(*acc);
    return code;
  }
  std::string inputs;
  for (const auto& s : lin.inputs) inputs += (inputs.empty() ? "" : ", ") + s;
  fmt::print("linear model of {} about {} at t = {:g} s: {} states ({} first order), {} inputs ({}), {} outputs\n",
             cs.name.empty() ? cs.path : cs.name, lin.equilibrium ? "rest" : "the motion", lin.t, lin.states.size(),
             2 * lin.states.size(), lin.inputs.size(), inputs.empty() ? "none: every joint prescribed" : inputs,
             lin.outputs.size());
  for (int i = 0; i < shown; ++i)
    fmt::print("  mode {}: {:.6g} Hz, damping ratio {:.3g}\n", i + 1, modes[static_cast<size_t>(i)].first,
               modes[static_cast<size_t>(i)].second);
  const bool first_order = static_cast<int>(lin.states.size()) <= LinearModel::kFileDenseStates;
  fmt::print("wrote {} (group linear: M, D, K, B sparse; Cq, Cv, Ca{}) from {} evaluations of the equations\n", o.output,
             first_order ? "; A, Bs, C, Ds" : "", lin.evaluations);
  if (acc) print_accuracy(*acc);
  return code;
}

}  // namespace rfem::app
