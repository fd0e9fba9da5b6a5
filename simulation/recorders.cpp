#include "recorders.hpp"
#include "state.hpp"

#include "../results/xdmf.hpp"

namespace rfem {

void Hdf5Recorder::begin(const RunInfo& info) {
  run_.reset();
  RunDescription d;
  d.options = info.options;
  d.inputs = info.inputs;
  d.flexible_every = info.flexible_every;
  d.threads = info.threads;
  d.sensor_columns = info.sensor_columns;
  d.sensor_units = info.sensor_units;
  run_ = info.resume ? file_.resume_run(info.name, info.model, d, *info.resume) : file_.begin_run(info.name, info.model, d);
}

void Hdf5Recorder::checkpoint(const PackedState& state) { run_->checkpoint(state.pieces()); }

void Hdf5Recorder::sample(const OutputSample& s) { run_->append(s); }

void Hdf5Recorder::measured(const std::vector<double>& row) { run_->append_sensors(row); }

void Hdf5Recorder::end(const RunResult& r) {
  RunOutcome o;
  o.status = r.status;
  o.t_reached = r.t_reached;
  o.stats = r.stats;
  run_->finish(o, r.wall_s, r.warnings);  // (the sensors' table was written row by row)
}

std::vector<std::string> write_views(const Case& cs, const Model& model, const std::string& results, const Warnings& warn) {
  if (cs.sim.flexible_every <= 0 || model.n() == 0) return {};
  try {  // (also of a failed run: what it computed)
    return write_xdmf(results);
  } catch (const std::exception& e) {
    if (warn) warn(std::string("no ParaView file: ") + e.what());
    return {};
  }
}

FileDescription describe(const Case& cs, const std::string& command_line, const std::string& procedure, long n,
                         long threads, long n_option) {
  FileDescription d;
  d.command_line = command_line;
  d.case_path = cs.path;
  d.case_text = cs.text;
  d.case_effective = cs.effective_text;
  for (const auto& o : cs.overrides) d.overrides += (d.overrides.empty() ? "" : "\n") + o;
  d.procedure = procedure;
  d.n = n;
  d.threads = threads;
  d.n_option = n_option;
  return d;
}

}  // namespace rfem
