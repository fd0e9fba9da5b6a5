#include "run_file.hpp"

#include "../results/errors.hpp"
#include "../results/writer.hpp"
#include "../simulation/common.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../simulation/simulation.hpp"
#include "reduction_error.hpp"
#include "resume.hpp"

namespace rfem {

FileRuns run_from_state(const Case& cs, const RunRequest& rq, const std::string& output, const std::string& made_by) {
  check_runnable(cs);
  SimulationOptions o;
  static_cast<RunOptions&>(o) = rq;
  o.output = output;
  o.made_by = made_by;
  o.driven_by = "";  // (the case's own laws: see plan_resume for why it still does not resume)
  try {
    o.state = std::make_shared<const SimulationState>(read_state(cs.sim.state));
  } catch (const CaseError& e) {  // (a results file's checkpoint that is not a state)
    throw CaseError(cs.path + ": simulation.state: " + e.what());
  } catch (const ResultsError& e) {
    throw CaseError(cs.path + ": simulation.state: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw CaseError(cs.path + ": simulation.state: " + e.what());
  }
  std::unique_ptr<Simulation> sim;
  try {
    sim = std::make_unique<Simulation>(cs, std::move(o));
  } catch (const std::invalid_argument& e) {  // another model's state
    throw CaseError(cs.path + ": simulation.state: " + cs.sim.state + ": " + e.what());
  }
  FileRuns out;
  out.model = sim->shared_model();
  sim->advance(sim->t_end());
  out.runs.push_back(sim->finish());
  if (!output.empty()) out.views = write_views(cs, *out.model, output, rq.warn);
  return out;
}

RefineResult refine_into_file(const Case& cs, RefineRequest rq, const std::string& output, const std::string& made_by) {
  check_refinement(cs, rq);  // (before the file exists)
  Parallelism p;
  p.threads = rq.threads;
  ResultsWriter file(output, describe(cs, made_by, "refine", -1, p.max_threads()));
  Hdf5Recorder recorder(file);
  rq.observers.insert(rq.observers.begin(), &recorder);
  const RefineResult res = refine(cs, rq);
  if (res.modes.empty()) file.write_refinement(rq.quantities, res.ns, res.tables, res.status);
  else file.write_refinement(rq.quantities, res.modes, res.tables, res.status, rq.ns[0]);
  if (!res.allowed.empty()) {  // the target, whether it was met, and what missed it
    if (rq.accuracy) file.write_attribute("refine", "accuracy", *rq.accuracy);
    if (res.dynamic) file.write_attribute("refine", "rtol", res.rtol), file.write_attribute("refine", "atol", res.atol);
    file.write_attribute("refine", "met", res.met ? 1.0 : 0.0);
    if (!res.shortfall.empty()) file.write_attribute("refine", "shortfall", res.shortfall);
  }
  file.close();
  return res;
}

FileRuns run_into_file(const Case& cs, RunRequest rq, const std::string& output, const std::string& made_by,
                       const std::function<void(const std::shared_ptr<const Model>&, const std::vector<JointInput>&)>& ready) {
  check_runnable(cs);
  if (!cs.sim.state.empty()) return run_from_state(cs, rq, output, made_by);
  FileRuns out;
  out.model = model_of(cs, rq.n);
  const std::vector<JointInput> inputs = joint_inputs(cs, rq.warn);
  if (ready) ready(out.model, inputs);
  Parallelism p;
  p.threads = rq.threads;
  const FileDescription d = describe(cs, made_by, to_string(cs.sim.procedure), out.model->n(), p.max_threads(), rq.n);
  auto file = std::make_unique<ResultsWriter>(output, d);  // (ResultsError for a path it cannot create)
  Hdf5Recorder recorder(*file);
  rq.observers.insert(rq.observers.begin(), &recorder);
  out.runs = run_case(cs, out.model, inputs, rq);
  write_reduction_error(*file, out.runs);
  file->close();
  // ParaView's view of every run that stored its poses (also of a failed run: what it computed).
  out.views = write_views(cs, *out.model, output, rq.warn);
  return out;
}

ModesStudy modes_into_file(const Case& cs, const ModesRequest& rq, const std::string& output, const std::string& made_by,
                           long threads) {
  ModesStudy s = modes_study(cs, rq);
  if (!output.empty()) {
    ResultsWriter file(output, describe(cs, made_by, "modes", s.model->n(), threads));
    write_modes(file, s);
    file.close();
  }
  return s;
}

LinearModel linearize_into_file(const Case& cs, const LinearizeRequest& rq, const std::string& output, const std::string& made_by) {
  LinearModel lin = linearize(cs, rq);
  if (!output.empty()) {
    ResultsWriter file(output, describe(cs, made_by, "linearize", static_cast<long>(lin.states.size() - lin.inputs.size()) / 6,
                                        rq.threads, rq.n));
    write_linear(file, lin);
    file.close();
  }
  return lin;
}

}  // namespace rfem
