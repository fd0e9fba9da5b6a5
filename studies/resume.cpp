#include "resume.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "../results/writer.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../simulation/sensors.hpp"
#include "../simulation/state.hpp"
#include "reduction_error.hpp"

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
    // A stepped run's inputs (a controller's, the caller's held torques) are not in the file: run
    // again, it would follow the case's own laws instead. (Files before `driven_by`: by their maker.)
    std::string driver = in.attribute("/", "driven_by");
    const std::string maker = in.attribute("/", "command_line");
    if (driver.empty() && (maker.find("run_controlled") != std::string::npos || maker.find("Simulation") != std::string::npos))
      driver = maker;
    if (!driver.empty())
      throw CaseError(path + ": its run was stepped by " + driver + " (a controller or held inputs from outside the case, "
                      "not in the file): `rfem run --resume` cannot continue it; run it again from Python, or start "
                      "rfem.Simulation(case, state=…) from a state you saved");
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
    if (!p.cs.sim.state.empty())
      throw CaseError(path + ": its run started from a saved state (simulation.state = \"" + p.cs.sim.state +
                      "\"), which keeps no checkpoints: it cannot be resumed; run the case again (it starts from the same state)");
    for (RunName r : runs_of(p.cs.sim.procedure)) {
      const std::string run = to_string(r);
      if (!in.has(run)) break;  // (not begun: it and the later runs run from t = 0)
      if (RunStatus::parse(in.attribute(run, "status")).is_completed()) {
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

namespace {

// Everything a resume keeps, checked before the file is opened for writing (that open already
// changes it), so a refused resume leaves the file byte for byte as it was: every series of a run
// kept whole or up to its checkpoint has the model's width and the rows kept, they read back
// (their Fletcher-32 checksums agree) and are finite; the checkpoint's state unpacks.
void verify_kept(const ResumePlan& plan, const Model& model) {
  try {
    const ResultsReader in(plan.path);
    auto verify = [&](const std::string& run, const std::vector<SeriesInfo>& series, long keep) {
      for (const SeriesInfo& s : series) {
        const std::string what = plan.path + ": " + run + "/" + s.name;
        const Table t = in.table(run + "/" + s.name);
        const long rows = keep < 0 ? t.rows : keep;
        if (t.cols != s.width() || t.rows < rows)
          throw CaseError(what + ": " + std::to_string(t.rows) + " × " + std::to_string(t.cols) + " does not fit " +
                          (keep < 0 ? "the case's model" : "the checkpoint (" + std::to_string(rows) + " rows × " +
                                                               std::to_string(s.width()) + ")") +
                          ": not resumed");
        for (long i = 0; i < rows * t.cols; ++i)
          if (!std::isfinite(t.data[static_cast<size_t>(i)]))
            throw CaseError(what + ": row " + std::to_string(i / t.cols + 1) + " is not finite (damaged): not resumed");
      }
    };
    auto layout_of = [&](const std::string& run) {
      const bool rigid = plan.cs.sim.procedure == Procedure::Paper && run == to_string(RunName::Rigid);
      return run_layout(rigid ? rigidify(model) : model, plan.cs.sim.flexible_every);
    };
    for (const std::string& run : plan.done) {
      const RunLayout l = layout_of(run);
      verify(run, l.series, -1);
      verify(run, l.flexible, -1);
    }
    // The sensors' table (a row per output, NaN allowed: a strain gauge on a rigid link) must hold the
    // checkpoint's rows too: a file whose run wrote it only at its end (an older rfem) is refused.
    const long sensor_cols = plan.cs.sensors.empty() ? 0 : static_cast<long>(SensorBank(plan.cs, model).columns().size()) + 1;
    for (const auto& [run, c] : plan.resume) {
      const RunLayout l = layout_of(run);
      verify(run, l.series, c.rows);
      verify(run, l.flexible, c.flexible_rows);
      if (sensor_cols > 0) {
        const std::string what = plan.path + ": " + run + "/sensors";
        if (!in.has(run + "/sensors"))
          throw CaseError(what + ": missing (written by an rfem that stored the sensors at a run's end): not resumed, run the case again");
        const Table t = in.table(run + "/sensors");
        if (t.cols != sensor_cols || t.rows < c.rows)
          throw CaseError(what + ": " + std::to_string(t.rows) + " × " + std::to_string(t.cols) + " does not fit the checkpoint (" +
                          std::to_string(c.rows) + " rows × " + std::to_string(sensor_cols) + "): not resumed");
      }
      try {
        RunState::unpack(c.state);
      } catch (const std::invalid_argument& e) {
        throw CaseError(plan.path + ": " + run + ": " + e.what() + ": not resumed");
      }
    }
  } catch (const ResultsError& e) {
    throw CaseError(std::string(e.what()) + ": not resumed");
  }
}

}  // namespace

std::vector<RunResult> resume_case(const ResumePlan& plan, RunRequest rq) {
  const Case& cs = plan.cs;
  if (plan.finished()) return {};
  const auto model = model_of(cs, plan.n);
  const std::vector<JointInput> inputs = joint_inputs(cs, rq.warn);
  verify_kept(plan, *model);
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
  write_reduction_error(file, runs);  // (of the runs run now: with their whole runs' peaks)
  file.close();
  // Series and sensor rows kept in memory hold only what came after the checkpoint: the whole run is
  // in the file.
  {
    const ResultsReader in(plan.path);
    for (RunResult& r : runs)
      if (r.sensors.cols > 0 && in.has(r.name + "/sensors")) r.sensors = in.table(r.name + "/sensors");
  }
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

namespace rfem {

SimulationState checkpoint_state(const std::string& results) {
  const ResumePlan plan = plan_resume(results);
  if (plan.cs.sim.procedure != Procedure::Single)
    throw CaseError(results + ": its procedure runs " + std::to_string(runs_of(plan.cs.sim.procedure).size()) +
                    " runs: a simulation's state is a single run's (rfem run --resume goes on with this file)");
  const auto c = plan.resume.find(to_string(RunName::Run));
  if (c == plan.resume.end() || c->second.state.empty())
    throw CaseError(results + (plan.finished() ? ": its run completed: no state is kept at its end (a checkpoint is a killed run's)"
                                               : ": its run wrote no checkpoint to go on from"));
  SimulationState s;
  try {
    s = RunState::unpack(c->second.state).state;
  } catch (const std::invalid_argument& e) {
    throw CaseError(results + ": run: " + e.what());
  }
  s.model = model_signature(*model_of(plan.cs, plan.n), joint_inputs(plan.cs));
  return s;
}

SimulationState read_state(const std::string& path) {
  bool state_file = false;
  {
    const ResultsReader in(path);  // (ResultsError naming the file for what is not one)
    state_file = !in.attribute("state", "model").empty();
  }
  return state_file ? load_state(path) : checkpoint_state(path);
}

}  // namespace rfem
