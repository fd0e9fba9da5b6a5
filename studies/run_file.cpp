#include "rfem/studies/run_file.hpp"

#include "rfem/results/errors.hpp"
#include "rfem/studies/common.hpp"
#include "rfem/studies/inputs.hpp"
#include "rfem/studies/recorders.hpp"

namespace rfem {

FileRuns run_into_file(const Case& cs, RunRequest rq, const std::string& output, const std::string& made_by,
                       const std::function<void(const std::shared_ptr<const Model>&, const std::vector<JointInput>&)>& ready) {
  check_runnable(cs);
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
  file->close();
  // ParaView's view of every run that stored its poses (also of a failed run: what it computed).
  out.views = write_views(cs, *out.model, output, rq.warn);
  return out;
}

}  // namespace rfem
