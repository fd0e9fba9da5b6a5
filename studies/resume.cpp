#include "rfem/studies/resume.hpp"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "rfem/results/writer.hpp"
#include "rfem/studies/inputs.hpp"
#include "rfem/studies/recorders.hpp"

namespace rfem {

bool ResumePlan::finished() const {
  for (RunName r : runs_of(cs.sim.procedure))
    if (std::find(done.begin(), done.end(), to_string(r)) == done.end()) return false;
  return true;
}

ResumePlan plan_resume(const std::string& path) {
  ResumePlan p;
  p.path = path;
  if (!std::filesystem::exists(path)) throw CaseError(path + ": no such results file to resume");
  try {
    const ResultsReader in(path);
    const std::string procedure = in.attribute("/", "procedure");
    if (procedure != "single" && procedure != "paper")
      throw CaseError(path + ": procedure '" + procedure + "': only the runs of `rfem run` (single, paper) resume");
    const double n = in.number("/", "n_option");
    if (!(n >= 0))
      throw CaseError(path + ": records no n_option (written by an older rfem): run the case again instead");
    p.n = static_cast<int>(n);
    const std::string case_path = in.attribute("/", "case_path");
    std::vector<std::string> overrides;
    std::istringstream lines(in.attribute("/", "overrides"));
    for (std::string line; std::getline(lines, line);)
      if (!line.empty()) overrides.push_back(line);
    const auto slash = case_path.find_last_of('/');
    try {
      p.cs = parse_case(in.attribute("/", "case_text"), case_path, overrides,
                        slash == std::string::npos ? std::string() : case_path.substr(0, slash + 1));
    } catch (const std::exception& e) {
      throw CaseError(path + ": its case does not read any more: " + e.what());
    }
    for (RunName r : runs_of(p.cs.sim.procedure)) {
      const std::string run = to_string(r);
      if (!in.has(run)) break;  // (not begun: it and the later runs run from t = 0)
      if (in.attribute(run, "status") == "completed") {
        p.done.push_back(run);
        continue;
      }
      if (std::optional<Checkpoint> c = read_checkpoint(in, run)) p.resume.emplace(run, std::move(*c));
      break;
    }
  } catch (const ResultsError& e) {
    throw CaseError(e.what());
  }
  return p;
}

std::vector<RunResult> resume_case(const ResumePlan& plan, RunRequest rq) {
  const Case& cs = plan.cs;
  if (plan.finished()) return {};
  const auto model = model_of(cs, plan.n);
  const std::vector<JointInput> inputs = joint_inputs(cs, rq.warn);
  rq.n = plan.n;
  rq.runs.clear();
  rq.done = plan.done;
  rq.resume = plan.resume;
  ResultsWriter file = [&] {
    try {
      return ResultsWriter(plan.path, Reopen{});
    } catch (const ResultsError& e) {
      throw CaseError(e.what());
    }
  }();
  Hdf5Recorder recorder(file);
  rq.observers.insert(rq.observers.begin(), &recorder);
  std::vector<RunResult> runs = run_case(cs, model, inputs, rq);
  file.close();
  // Series kept in memory hold only what came after the checkpoint: the whole run is in the file.
  if (rq.keep_series) {
    const ResultsReader in(plan.path);
    for (RunResult& r : runs) {
      auto s = std::make_shared<RunSeries>();
      s->layout = run_layout(*r.model, cs.sim.flexible_every);
      for (const SeriesInfo& info : s->layout.series) {
        Table t = in.table(r.name + "/" + info.name);
        s->rows = t.rows;
        s->data.push_back(std::move(t.data));
      }
      for (const SeriesInfo& info : s->layout.flexible) {
        Table t = in.table(r.name + "/" + info.name);
        s->flexible_rows = t.rows;
        s->flexible.push_back(std::move(t.data));
      }
      r.series = std::move(s);
    }
  }
  return runs;
}

}  // namespace rfem
