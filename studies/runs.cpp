#include "runs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "../core/check.hpp"
#include "../core/positions.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/sensors.hpp"
#include "../simulation/simulation.hpp"
#include "../simulation/state.hpp"
#include "../simulation/validity.hpp"
#include "reduction_error.hpp"
#include "run_file.hpp"

namespace rfem {

namespace {

// One run of the procedure: a Simulation advanced to t_end (resumed from its checkpoint, if any).
RunResult run_one(const std::string& name, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs,
                  const Case& cs, const RunRequest& rq) {
  SimulationOptions o;
  static_cast<RunOptions&>(o) = rq;
  o.driven_by = "";  // (the case's own laws)
  const auto from = rq.resume.find(name);
  Simulation sim(cs, name, std::move(model), inputs, std::move(o), from == rq.resume.end() ? nullptr : &from->second);
  sim.advance(sim.t_end());
  return sim.finish();
}

}  // namespace

std::vector<RunResult> run_case(const Case& cs, const RunRequest& rq) {
  check_runnable(cs);
  if (!cs.sim.state.empty()) return run_from_state(cs, rq, "", "").runs;
  const auto model = model_of(cs, rq.n);
  return run_case(cs, model, joint_inputs(cs, rq.warn), rq);
}

std::vector<RunResult> run_case(const Case& cs, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs,
                                const RunRequest& rq) {
  if (!model) throw std::invalid_argument("run_case: no model");
  check_runnable(cs);
  if (!cs.sim.state.empty())
    throw CaseError(cs.path + ": simulation.state: a run from a saved state builds its own model (run_case(case, request))");
  if (static_cast<int>(inputs.size()) != model->m())
    throw std::invalid_argument("run_case: one input per joint is required (" + std::to_string(model->m()) + ")");
  const std::vector<RunName> all = runs_of(cs.sim.procedure);
  for (RunName r : rq.runs)
    if (std::find(all.begin(), all.end(), r) == all.end())
      throw CaseError(cs.path + ": simulation.procedure: " + to_string(cs.sim.procedure) + " has no run '" + to_string(r) + "'");
  // Asked for, and not completed before (a resumed study).
  auto wanted = [&](RunName r) {
    const std::string full = rq.prefix + to_string(r);
    return (rq.runs.empty() || std::find(rq.runs.begin(), rq.runs.end(), r) != rq.runs.end()) &&
           std::find(rq.done.begin(), rq.done.end(), full) == rq.done.end();
  };
  std::vector<RunResult> runs;
  auto go_on = [&] { return runs.empty() || (runs.back().completed() && !rq.stop.requested()); };
  if (cs.sim.procedure == Procedure::Paper) {
    for (size_t j = 0; j < inputs.size(); ++j)
      if (!inputs[j].prescribed())
        throw CaseError(cs.inputs[j].where + ": the paper procedure needs a motion law on every joint");
    const auto rigid = std::make_shared<const Model>(rigidify(*model));
    if (wanted(RunName::Rigid)) runs.push_back(run_one(rq.prefix + "rigid", rigid, inputs, cs, rq));
    if (wanted(RunName::Kinematic) && go_on()) runs.push_back(run_one(rq.prefix + "kinematic", model, inputs, cs, rq));
    if (wanted(RunName::Force) && go_on())
      runs.push_back(run_one(rq.prefix + "force", model, rigid_torque_inputs(rigid, inputs), cs, rq));
  } else if (wanted(RunName::Run)) {
    runs.push_back(run_one(rq.prefix + "run", model, inputs, cs, rq));
  }
  estimate_reduction_error(cs, *model, rq, runs);
  return runs;
}

}  // namespace rfem
