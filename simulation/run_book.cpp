#include "run_book.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "../core/check.hpp"
#include "../core/positions.hpp"
#include "inputs.hpp"
#include "sensors.hpp"
#include "state.hpp"
#include "validity.hpp"

namespace rfem {

RunSeries::View RunSeries::view(const std::string& wanted) const {
  std::string name = wanted;
  for (const auto& [alias, target] : layout.aliases)
    if (alias == name) name = target;
  for (size_t i = 0; i < layout.series.size(); ++i)
    if (layout.series[i].name == name) return {&layout.series[i], data[i].data(), rows};
  for (size_t i = 0; i < layout.flexible.size(); ++i)
    if (layout.flexible[i].name == name) return {&layout.flexible[i], flexible[i].data(), flexible_rows};
  for (const auto& [info, values] : layout.constants)
    if (info.name == name) return {&info, values.data(), static_cast<long>(values.size()) / info.width()};
  throw std::out_of_range("no series named '" + wanted + "'");
}

Table RunSeries::table(const std::string& name) const {
  const View v = view(name);
  Table t;
  t.rows = v.rows;
  t.cols = v.info->width();
  t.data.assign(v.data, v.data + t.rows * t.cols);
  return t;
}

std::vector<std::string> RunSeries::names() const {
  std::vector<std::string> out;
  for (const auto& s : layout.series) out.push_back(s.name);
  for (const auto& s : layout.flexible) out.push_back(s.name);
  for (const auto& [s, v] : layout.constants) out.push_back(s.name);
  for (const auto& [alias, target] : layout.aliases) out.push_back(alias);
  return out;
}

RunBook::RunBook(std::string name, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs, const Case& cs,
                 const RunOptions& rq, const IntegratorOptions& o, const Checkpoint* checkpoint, const RunState* resumed)
    : rq_(rq), o_(o), model_(std::move(model)), validity_(std::make_unique<ValidityMonitor>(*model_)),
      t0_(std::chrono::steady_clock::now()) {
  RunResult& s = s_;
  s.name = std::move(name);
  s.model = model_;
  for (const MountedLink& L : model_->links) s.peaks.push_back({L.name});
  if (!cs.sensors.empty()) {  // (first: the observers learn its columns)
    sensors_ = std::make_unique<SensorBank>(cs, *model_);
    s.sensor_columns = sensors_->columns();
    s.sensor_units = sensors_->units();
    s.sensors.cols = static_cast<long>(s.sensor_columns.size()) + 1;  // (time first)
    s.sensor_columns.insert(s.sensor_columns.begin(), "time");
    s.sensor_units.insert(s.sensor_units.begin(), "s");
  }
  const RunInfo info{s.name, model_, o, input_kinds(inputs), cs.sim.flexible_every, o.parallel.max_threads(), checkpoint,
                     s.sensor_columns, s.sensor_units};
  for (RunObserver* obs : rq.observers) obs->begin(info);
  if (checkpoint) {
    RFEM_CHECK_ARGUMENT(resumed != nullptr, "a checkpoint needs its unpacked state");
    for (RunObserver* obs : rq.observers)
      if (const std::string key = obs->state_key(); !key.empty()) {
        const std::vector<double>* x = resumed->find(key);
        if (!x) throw std::invalid_argument("run " + s.name + ": its checkpoint holds no state of " + key);
        obs->restore(*x);
      }
  }
  if (rq.keep_series) {
    s.series = std::make_shared<RunSeries>();
    s.series->layout = run_layout(*model_, cs.sim.flexible_every);
    s.series->data.resize(s.series->layout.series.size());
    s.series->flexible.resize(s.series->layout.flexible.size());
  }
  if (checkpoint) {  // the run's own summary (summary()), back
    const std::vector<double>& x = resumed->summary;
    const size_t links = s.peaks.size();
    if (x.size() < 6 + 3 * links || x[5] != static_cast<double>(links))
      throw std::invalid_argument("run " + s.name + ": its checkpoint is not of this model");
    s.samples = static_cast<long>(x[0]);
    wall_before_ = x[1];
    balance0_ = x[2];
    s.energy_drift = x[3];
    s.energy_scale = x[4];
    for (size_t l = 0; l < links; ++l) {
      s.peaks[l].u1 = x[6 + 3 * l];
      s.peaks[l].u2 = x[7 + 3 * l];
      s.peaks[l].theta = x[8 + 3 * l];
    }
    validity_->restore(std::vector<double>(x.begin() + static_cast<long>(6 + 3 * links), x.end()));
    if (checkpoint->rows != s.samples) throw std::invalid_argument("run " + s.name + ": its checkpoint is damaged (rows)");
  }
}

RunBook::~RunBook() = default;

void RunBook::sample(const OutputSample& x) {
  RunResult& s = s_;
  const Model& m = *model_;
  for (RunObserver* obs : rq_.observers) obs->sample(x);
  if (RunSeries* ser = s.series.get()) {
    sample_rows(m, ser->layout, x, rows_);
    for (size_t i = 0; i < rows_.size(); ++i) ser->data[i].insert(ser->data[i].end(), rows_[i].begin(), rows_[i].end());
    if (!ser->layout.flexible.empty() && ser->rows % ser->layout.flexible_every == 0) {
      flexible_rows(m, ser->layout, x, rows_);
      for (size_t i = 0; i < rows_.size(); ++i) ser->flexible[i].insert(ser->flexible[i].end(), rows_[i].begin(), rows_[i].end());
      ++ser->flexible_rows;
    }
    ++ser->rows;
  }
  for (size_t l = 0; l < s.peaks.size(); ++l) {
    const Vec3 u = tip_deflection(m, static_cast<int>(l), x.q);
    LinkPeaks& pk = s.peaks[l];
    pk.u1 = std::max(pk.u1, std::abs(u[0]));
    pk.u2 = std::max(pk.u2, std::abs(u[1]));
    pk.theta = std::max(pk.theta, std::abs(u[2]));
  }
  validity_->check(x.q, x.t);
  validity_->check_joints(x.q, x.v, x.tau, x.t);
  if (sensors_) {  // (their own random stream: the same readings whatever a controller asks)
    streams_before_ = sensors_->save();
    sensor_t_ = x.t;
    sensor_row_.assign(1, x.t);
    sensors_->read(x.q, x.v, x.a, x.tau, sensor_row_, 1);
    s.sensors.data.insert(s.sensors.data.end(), sensor_row_.begin(), sensor_row_.end());
    ++s.sensors.rows;
    for (RunObserver* obs : rq_.observers) obs->measured(sensor_row_);
  }
  const double bal = x.energy_balance();
  if (std::isnan(balance0_)) balance0_ = bal;
  s.energy_drift = std::max(s.energy_drift, std::abs(bal - balance0_));
  s.energy_scale = std::max({s.energy_scale, x.energy.kinetic, std::abs(x.energy.elastic), std::abs(x.input_work)});
  ++s.samples;
  // A diverged solution ends the run (failed: "diverged at t = …"), every row up to here kept.
  if (const std::string why = validity_->diverged(x.q, x.t); !why.empty()) throw std::runtime_error(why);
}

std::vector<double> RunBook::sensor_streams(double t) const {
  if (!sensors_) return {};
  return t == sensor_t_ ? streams_before_ : sensors_->save();
}

void RunBook::skip_sensor_row() {
  if (sensors_) sensors_->skip(1);
}

void RunBook::restore_sensor_streams(const std::vector<double>& x) {
  if (sensors_) sensors_->restore(x);
  else if (!x.empty()) throw std::invalid_argument("the state holds the noise of sensors that the case does not have");
}

double RunBook::wall() const {
  return wall_before_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
}

void RunBook::checkpoint(const SimulationState& st) {
  // The run's own summary, then every observer's state; the simulation's state is pointed to.
  const RunResult& s = s_;
  RunState x;
  x.summary = {static_cast<double>(s.samples), wall(), balance0_, s.energy_drift, s.energy_scale, static_cast<double>(s.peaks.size())};
  for (const LinkPeaks& pk : s.peaks) x.summary.insert(x.summary.end(), {pk.u1, pk.u2, pk.theta});
  const std::vector<double> v = validity_->save();
  x.summary.insert(x.summary.end(), v.begin(), v.end());
  for (RunObserver* obs : rq_.observers)
    if (const std::string key = obs->state_key(); !key.empty()) x.add(key, obs->save());
  const PackedState packed(st, x.summary, x.observers);
  for (RunObserver* obs : rq_.observers) obs->checkpoint(packed);
}

RunResult RunBook::end(RunOutcome r) {
  RunResult& s = s_;
  // Progress once more where the run ended, so every run reports at least once however short it is
  // (a caller's answer must not depend on wall time); a throwing callback fails a completed run.
  if (rq_.progress && r.t_reached > 0) {
    try {
      rq_.progress({s.name, r.t_reached, o_.t_end, r.stats.steps});
    } catch (const std::exception& e) {
      if (r.status.is_completed()) r.status = RunStatus::failed(e.what());
    }
  }
  s.wall_s = wall();
  s.status = r.status;
  s.stats = r.stats;
  s.t_reached = r.t_reached;
  s.warnings = validity_->warnings("run " + s.name);
  if (rq_.warn)
    for (const auto& w : s.warnings) rq_.warn(w);
  for (RunObserver* obs : rq_.observers) obs->end(s);
  return s;
}

void check_runnable(const Case& cs) {
  if (!cs.has_simulation) throw CaseError(cs.path + ": simulation: missing table (t_end, output_dt, …) for a run");
  // A case without joints runs too: its links are clamped to the ground (a structure vibrating
  // under gravity or from an undeformed start; its linear model is rfem modes' M, D, K).
}

}  // namespace rfem
