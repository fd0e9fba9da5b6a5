#include "simulation.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "../core/check.hpp"
#include "../core/positions.hpp"
#include "../results/errors.hpp"
#include "../results/writer.hpp"
#include "common.hpp"
#include "inputs.hpp"
#include "recorders.hpp"
#include "sensors.hpp"

namespace rfem {

namespace {

// What a joint holds (SimulationState::drives: the mode, then τ, q_ref, q̇_ref, τ_ff).
constexpr int kHeldNone = 0, kHeldTorque = 1, kHeldReference = 2, kDriveValues = 5;

// A force-input joint's law with a value the caller may hold instead (zero-order hold): a torque,
// or a PD reference with the case's gains.
class HeldLaw : public TorqueLaw {
 public:
  explicit HeldLaw(std::shared_ptr<TorqueLaw> base) : base_(std::move(base)) {}
  double at(double t) const override {
    return mode == kHeldTorque ? tau : mode == kHeldReference ? tau_ff : base_->at(t);
  }
  double at(double t, double q, double v) const override {
    if (mode == kHeldTorque) return tau;
    if (mode == kHeldReference) return tau_ff + base_->stiffness() * (q_ref - q) + base_->damping() * (v_ref - v);
    return base_->at(t, q, v);
  }
  // −∂τ/∂q, −∂τ/∂v of the law in force (the power's first-order update uses them): none for a held
  // torque. (The Newton matrix keeps the case's gains, set once: they only speed Newton up.)
  double stiffness() const override { return mode == kHeldTorque ? 0.0 : base_->stiffness(); }
  double damping() const override { return mode == kHeldTorque ? 0.0 : base_->damping(); }
  std::vector<double> breakpoints() const override { return base_->breakpoints(); }
  // A digital law (pd with sample_time) keeps sampling under a held value: released, it goes on
  // from its own last sample, as the controller it models would.
  double sample_time() const override { return base_->sample_time(); }
  void sample(double t, double q, double v) override { base_->sample(t, q, v); }
  std::vector<double> memory() const override { return base_->memory(); }
  void restore(const std::vector<double>& m) override { base_->restore(m); }
  bool feedback() const { return base_->stiffness() > 0 || base_->damping() > 0; }
  int mode = kHeldNone;
  double tau = 0.0, q_ref = 0.0, v_ref = 0.0, tau_ff = 0.0;

 private:
  std::shared_ptr<TorqueLaw> base_;
};

const char* kAxisNames[6] = {"x1", "x2", "x3", "phi1", "phi2", "phi3"};

}  // namespace

struct Simulation::Impl {
  Case cs;
  SimulationOptions opts;  // (observers: the results file's recorder first, then the caller's)
  IntegratorOptions o;
  std::shared_ptr<const Model> model;
  std::vector<JointInput> inputs;
  std::vector<std::shared_ptr<HeldLaw>> held;  // per joint (null: prescribed motion)
  std::string signature;
  std::unique_ptr<ResultsWriter> file;
  std::unique_ptr<Hdf5Recorder> recorder;
  std::unique_ptr<RunBook> book;
  std::unique_ptr<SensorBank> sensors;  // the snapshots' (the book records its own)
  std::unique_ptr<EquationsOfMotion> eq;
  std::unique_ptr<Stepper> stepper;  // (after eq: it refers to it)
  SampleSink sink;
  RunControl control;
  IntegratorState resume;
  RunState resumed;                     // a procedure's run from its checkpoint
  std::unique_ptr<SampleEmitter> emit;  // (after sink and control: it refers to them)
  RunStatus status;
  bool changed = false;  // a held value changed since the last step
  VecX scratch;          // a snapshot's residual
  std::optional<RunResult> result;
  struct PendingTable {
    std::string name;
    Table table;
    std::vector<std::string> columns, units;
    std::string description;
  };
  std::vector<PendingTable> tables;

  void init(const Case& c, const std::string& name, const Checkpoint* checkpoint);

  int joint(const std::string& name) const {
    for (int j = 0; j < model->m(); ++j)
      if (model->joints[j].name == name) return j;
    std::string names;
    for (const Joint& J : model->joints) names += (names.empty() ? "" : ", ") + J.name;
    throw std::invalid_argument("no joint named '" + name + "' (joints: " + names + ")");
  }
  HeldLaw& law(const std::string& name, const char* what) {
    const int j = joint(name);
    if (!held[j])
      throw std::invalid_argument("joint '" + name + "' follows a prescribed motion: " + what +
                                  " needs a force-input joint (its torque is an output here)");
    return *held[j];
  }
  void apply_drives(const std::vector<double>& d) {
    if (d.size() != static_cast<size_t>(kDriveValues * model->m()))
      throw std::invalid_argument("the state's drives do not fit this model");
    for (int j = 0; j < model->m(); ++j) {
      const double* x = d.data() + kDriveValues * j;
      if (!held[j]) continue;
      held[j]->mode = static_cast<int>(x[0]);
      held[j]->tau = x[1];
      held[j]->q_ref = x[2];
      held[j]->v_ref = x[3];
      held[j]->tau_ff = x[4];
    }
  }
  // The drives, the laws' memory and the sensors' streams of a state (a caller's or a checkpoint's;
  // its integrator's state is the stepper's start).
  void go_on_from(const SimulationState& from) {
    if (!from.drives.empty()) apply_drives(from.drives);         // (a checkpoint of layout 1 has none)
    if (!from.laws.empty()) restore_law_memory(inputs, from.laws);  // (version 1: the laws start afresh)
    // (version < 3: the noise starts afresh; a case without sensors has none to go on with)
    if (from.sensors.empty() || !sensors) return;
    const size_t half = from.sensors.size() / 2;
    if (from.sensors.size() % 2 != 0) throw std::invalid_argument("the state's sensors' noise is damaged (an odd count)");
    book->restore_sensor_streams(std::vector<double>(from.sensors.begin(), from.sensors.begin() + static_cast<long>(half)));
    sensors->restore(std::vector<double>(from.sensors.begin() + static_cast<long>(half), from.sensors.end()));
  }
  // A state but for its integrator's, at time t (SimulationState: drives, laws, sensors).
  SimulationState state_at(double t) const;
  void bring_inputs_up_to_date() {
    if (!changed || status.kind != RunStatus::Kind::Running) return;
    stepper->inputs_changed();
    changed = false;
  }
  void require_running(const char* what) const {
    if (result) throw std::logic_error(std::string(what) + ": the simulation has finished (" + result->status.to_string() + ")");
  }
  // The stepper's state (a run without unknowns has none to read).
  IntegratorState now(const char* what) const {
    if (!stepper || !stepper->has_state())
      throw std::logic_error(std::string(what) + ": the run has no state (every joint prescribed, no flexible link, or it "
                                                 "failed at its start)");
    return stepper->state();
  }
};

Simulation::Simulation(const Case& cs, SimulationOptions opts) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  check_runnable(cs);
  m.opts = std::move(opts);
  m.model = model_of(cs, m.opts.n);
  m.inputs = rfem::joint_inputs(cs, m.opts.warn);
  m.init(cs, "run", nullptr);
}

Simulation::Simulation(const Case& cs, std::string name, std::shared_ptr<const Model> model, std::vector<JointInput> inputs,
                       SimulationOptions opts, const Checkpoint* checkpoint)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  RFEM_CHECK_ARGUMENT(model != nullptr, "no model");
  RFEM_CHECK_ARGUMENT_SIZE(inputs.size(), model->m(), "inputs");
  check_runnable(cs);
  m.opts = std::move(opts);
  m.model = std::move(model);
  m.inputs = std::move(inputs);
  m.init(cs, name, checkpoint);
}

void Simulation::Impl::init(const Case& c, const std::string& name, const Checkpoint* checkpoint) {
  Impl& m = *this;
  m.cs = c;
  const Case& cs = m.cs;
  m.o = cs.sim.options;
  m.o.parallel.threads = m.opts.threads;
  m.signature = model_signature(*m.model, m.inputs);
  m.held.resize(m.inputs.size());
  for (size_t j = 0; j < m.inputs.size(); ++j)
    if (!m.inputs[j].prescribed()) {
      m.held[j] = std::make_shared<HeldLaw>(m.inputs[j].torque);
      m.inputs[j].torque = m.held[j];
    }
  const SimulationState* from = m.opts.state.get();
  RFEM_CHECK_ARGUMENT(!(from && checkpoint), "a run starts from a state or resumes from a checkpoint, not both");
  const bool callers = !m.opts.driven_by.empty();  // a run whose inputs come from its caller
  if (from) {
    if (from->model != m.signature)
      throw std::invalid_argument("the state is of another model: it has " + from->model + "; this simulation " + m.signature);
    if (!(from->time() >= 0))
      throw std::invalid_argument(fmt::format("the state's time {:.6g} s is negative", from->time()));
    if (!(from->time() < m.o.t_end))
      throw std::invalid_argument(fmt::format("the state's time {:.10g} s is not before simulation.t_end = {:.10g} s: "
                                              "nothing is left to run (a later t_end: --set simulation.t_end=…)",
                                              from->time(), m.o.t_end));
    // (a state put together by hand: its integrator's entries are checked where it is unpacked)
    IntegratorState::unpack(from->integrator.pack(), -1);
    m.resume = from->integrator;
    m.resume.stats = {};
    // The outputs after the state's time, on this run's grid (the state's own row is written below).
    const double t = from->time();
    long k = static_cast<long>(std::floor(t / m.o.output_dt)) + 1;
    while (k > 1 && output_time(m.o, k - 1) > t) --k;
    m.resume.next_output = std::min(k, output_count(m.o) + 1);
    m.control.resume = &m.resume;
  }
  if (checkpoint) {
    m.resumed = RunState::unpack(checkpoint->state);
    m.control.resume = &m.resumed.state.integrator;
  }
  if (!m.opts.output.empty()) {
    Parallelism p;
    p.threads = m.opts.threads;
    FileDescription d = describe(cs, m.opts.made_by, "single", m.model->n(), p.max_threads(), m.opts.n);
    d.driven_by = m.opts.driven_by;
    m.file = std::make_unique<ResultsWriter>(m.opts.output, d);  // (ResultsError for a path it cannot create)
    m.recorder = std::make_unique<Hdf5Recorder>(*m.file);
    m.opts.observers.insert(m.opts.observers.begin(), m.recorder.get());
  }
  // Checkpoints only where `rfem run --resume` can go on: a case's own run from t = 0.
  if (callers || from) m.opts.checkpoint_interval = 0.0;
  m.book = std::make_unique<RunBook>(name, m.model, m.inputs, cs, m.opts, m.o, checkpoint, checkpoint ? &m.resumed : nullptr);
  if (!cs.sensors.empty()) m.sensors = std::make_unique<SensorBank>(cs, *m.model);
  try {
    m.eq = std::make_unique<EquationsOfMotion>(m.model, m.inputs, m.o.forces, m.opts.stop, m.o.linear_solver, m.o.parallel,
                                               m.o.kind == IntegratorKind::Bdf);  // (IDA's solve needs K on its own)
  } catch (const std::exception& e) {
    if (callers || from) throw;
    m.status = RunStatus::failed(e.what());  // (a case's run: its record says why)
    return;
  }
  if (from) {
    m.go_on_from(*from);
  } else if (checkpoint) {
    if (m.sensors && m.resumed.state.sensors.empty())
      throw std::invalid_argument("run " + name + ": its checkpoint holds no state of the sensors' noise (written by an older "
                                  "rfem): not resumed, run the case again");
    try {
      m.go_on_from(m.resumed.state);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("run " + name + ": its checkpoint: " + e.what());
    }
    // A checkpoint at an output the run recorded holds the streams before its row (a state's):
    // the resumed run does not record it again.
    const long k = m.resumed.state.integrator.next_output - 1;
    if (k >= 0 && output_time(m.o, k) == m.resumed.state.time()) m.book->skip_sensor_row();
  }  // (after the equations took the case laws' gains for Newton)
  if (m.eq->unknowns() == 0 && (callers || from))
    throw CaseError(cs.path + ": joints: every joint follows a prescribed motion and there is no flexible link: nothing to step "
                              "(rfem run computes its torques)");
  m.sink = [&m](const OutputSample& x) { m.book->sample(x); };
  m.control.stop = m.opts.stop;
  if (m.opts.progress) {
    const std::string run = name;
    m.control.heartbeat = [&m, run](double t, long steps) { m.opts.progress({run, t, m.o.t_end, steps}); };
  }
  m.control.heartbeat_interval = m.opts.progress_interval;
  m.control.checkpoint_interval = m.opts.checkpoint_interval;
  m.control.checkpoint = [&m](IntegratorState& st) {  // (the stepper's vectors lent, not copied)
    SimulationState s = m.state_at(st.t);
    s.model.clear();  // (a checkpoint belongs to its run's model)
    std::swap(s.integrator, st);
    try {
      m.book->checkpoint(s);
    } catch (...) {
      std::swap(s.integrator, st);
      throw;
    }
    std::swap(s.integrator, st);
  };
  m.emit = std::make_unique<SampleEmitter>(m.sink, m.control);
  try {
    m.stepper = make_stepper(*m.eq, m.o);
    m.status = m.stepper->start(*m.emit);
    if (from && m.status.kind == RunStatus::Kind::Running) {  // the state's own row
      const IntegratorState& x = m.resume;
      if (!(*m.emit)(m.eq->sample(x.t, x.q.data(), x.v.data(), x.a.data(), x.dissipated, x.input_work)))
        m.status = m.emit->failure();
      // A row the run the state came from did not record (its time is off the output grid) draws no
      // noise from the streams the later rows share with that run.
      const long k = m.resume.next_output - 1;
      if (!from->sensors.empty() && m.sensors && !(k >= 0 && output_time(m.o, k) == x.t))
        m.book->restore_sensor_streams(std::vector<double>(from->sensors.begin(),
                                                           from->sensors.begin() + static_cast<long>(from->sensors.size() / 2)));
    }
  } catch (const std::invalid_argument& e) {
    if (callers || from) throw;  // a state that does not fit, options a caller gave
    m.status = RunStatus::failed(e.what());  // (a case's run: a checkpoint that does not fit it)
  } catch (const std::exception& e) {
    m.status = RunStatus::failed(callers || from ? at_start(e.what()) : e.what());
  }
}

Simulation::~Simulation() {
  if (!impl_ || impl_->result) return;
  try {
    finish();
  } catch (...) {  // (a destructor reports nothing; finish() is the caller's way to hear of it)
  }
}

Simulation::Simulation(Simulation&&) noexcept = default;

const Model& Simulation::model() const { return *impl_->model; }
std::shared_ptr<const Model> Simulation::shared_model() const { return impl_->model; }
double Simulation::time() const { return impl_->stepper ? impl_->stepper->time() : 0.0; }
double Simulation::t_end() const { return impl_->o.t_end; }


VecX Simulation::q() const {
  const Impl& m = *impl_;
  const IntegratorState x = m.now("q");
  return m.eq->full_coordinates(x.t, x.q.data(), 0);
}

VecX Simulation::v() const {
  const Impl& m = *impl_;
  const IntegratorState x = m.now("v");
  return m.eq->full_coordinates(x.t, x.v.data(), 1);
}

std::vector<std::string> Simulation::coordinate_names() const {
  const Model& md = *impl_->model;
  std::vector<std::string> names(md.dof());
  for (size_t l = 0; l < md.links.size(); ++l)
    for (int k = 0; k < md.links[l].n(); ++k)
      for (int a = 0; a < Model::rfe_dofs; ++a)
        names[md.rfe_index(static_cast<int>(l), k) + a] = md.links[l].name + "/rfe" + std::to_string(k + 1) + "/" + kAxisNames[a];
  for (int j = 0; j < md.m(); ++j) names[md.joint_index(j)] = md.joints[j].name;
  return names;
}

std::vector<std::string> Simulation::joint_names() const {
  std::vector<std::string> names;
  for (const Joint& j : impl_->model->joints) names.push_back(j.name);
  return names;
}

std::vector<std::string> Simulation::joint_inputs() const { return input_kinds(impl_->inputs); }

void Simulation::set_torque(const std::string& joint, double tau) {
  Impl& m = *impl_;
  HeldLaw& law = m.law(joint, "set_torque");
  if (!std::isfinite(tau)) throw std::invalid_argument("set_torque: joint '" + joint + "': the torque must be finite");
  law.mode = kHeldTorque;
  law.tau = tau;
  m.changed = true;
}

void Simulation::set_reference(const std::string& joint, double q_ref, double v_ref, double tau_ff) {
  Impl& m = *impl_;
  HeldLaw& law = m.law(joint, "set_reference");
  if (!law.feedback())
    throw std::invalid_argument("set_reference: joint '" + joint + "' has no PD law in the case (input kind \"pd\"): "
                                "hold a torque with set_torque");
  if (!std::isfinite(q_ref) || !std::isfinite(v_ref) || !std::isfinite(tau_ff))
    throw std::invalid_argument("set_reference: joint '" + joint + "': the reference must be finite");
  law.mode = kHeldReference;
  law.q_ref = q_ref;
  law.v_ref = v_ref;
  law.tau_ff = tau_ff;
  m.changed = true;
}

void Simulation::release(const std::string& joint) {
  Impl& m = *impl_;
  m.law(joint, "release").mode = kHeldNone;
  m.changed = true;
}

RunStatus Simulation::advance(double t) {
  Impl& m = *impl_;
  m.require_running("advance");
  const double now = time();
  // A time a round-off past t_end (a sum of sample times) is t_end.
  if (t > m.o.t_end && t <= m.o.t_end * (1 + 1e-12)) t = m.o.t_end;
  if (!std::isfinite(t) || t < now || t > m.o.t_end)
    throw std::invalid_argument(fmt::format("advance: t = {:.10g} s is {}: it must lie between the simulation's time {:.10g} s "
                                            "and simulation.t_end = {:.10g} s",
                                            t, !std::isfinite(t) ? "not finite" : t < now ? "in the past" : "after the run's end",
                                            now, m.o.t_end));
  if (m.status.kind != RunStatus::Kind::Running || t == now) return m.status;
  try {
    m.bring_inputs_up_to_date();
    m.status = m.stepper->advance(t, *m.emit);
  } catch (const std::exception& e) {
    m.status = RunStatus::failed(e.what());
  }
  return m.status;
}

void Simulation::sample_every(double period, long first, std::function<void(double t)> f) {
  Impl& m = *impl_;
  m.require_running("sample_every");
  RFEM_CHECK_ARGUMENT(period > 0 && std::isfinite(period) && first >= 0 && f, "sample_every: a positive period, a first sample and a function");
  RFEM_CHECK_ARGUMENT(m.stepper != nullptr, "sample_every: the run failed at its start");
  Sampler x;
  x.period = period;
  x.next = first;  // (one at or before now is skipped: a sample at now is the caller's)
  x.needs_state = true;
  const double last = m.o.t_end * (1 - 1e-12);  // (none at t_end: nothing is left to hold)
  x.sample = [&m, f = std::move(f), last](double t) {
    if (t >= last) return false;
    m.changed = false;  // (every earlier change is in force: the stepper brought it up to date)
    f(t);
    const bool changed = m.changed;
    m.changed = false;  // (the stepper evaluates the new inputs now)
    return changed;
  };
  m.stepper->add_sampler(std::move(x));
}

Snapshot Simulation::snapshot() {
  Impl& m = *impl_;
  m.require_running("snapshot");
  m.bring_inputs_up_to_date();
  const IntegratorState x = m.now("snapshot");
  // The equations at the state give the joints' torques (applied, or required by a prescribed
  // motion); a snapshot needs no energies or momentum (an output sample's extra passes).
  m.scratch.resize(m.eq->unknowns());
  m.eq->residual(x.t, x.q.data(), x.v.data(), x.a.data(), m.scratch.data());
  const VecX q = m.eq->full_coordinates(x.t, x.q.data(), 0), v = m.eq->full_coordinates(x.t, x.v.data(), 1);
  Snapshot y;
  y.t = x.t;
  y.joint_q = m.model->joint_coords(q);
  y.joint_v = m.model->joint_coords(v);
  y.joint_tau = m.eq->torques(x.t);
  for (size_t l = 0; l < m.model->links.size(); ++l) {
    y.tip_position.push_back(tip_position(*m.model, static_cast<int>(l), q));
    y.tip_deflection.push_back(tip_deflection(*m.model, static_cast<int>(l), q));
  }
  if (m.sensors) {
    std::vector<double> values;
    m.sensors->read(q, v, m.eq->full_coordinates(x.t, x.a.data(), 2), y.joint_tau, values, 0);
    size_t k = 0;
    for (size_t i = 0; i < m.sensors->size(); ++i) {
      const auto w = static_cast<size_t>(m.sensors->width(i));
      y.sensors.emplace_back(m.sensors->spec(i).name, std::vector<double>(values.begin() + static_cast<long>(k),
                                                                          values.begin() + static_cast<long>(k + w)));
      k += w;
    }
  }
  return y;
}

SimulationState Simulation::Impl::state_at(double t) const {
  SimulationState s;
  s.model = signature;
  s.drives.assign(static_cast<size_t>(kDriveValues * model->m()), 0.0);
  for (int j = 0; j < model->m(); ++j)
    if (const HeldLaw* h = held[j].get()) {
      double* d = s.drives.data() + kDriveValues * j;
      d[0] = h->mode;
      d[1] = h->tau;
      d[2] = h->q_ref;
      d[3] = h->v_ref;
      d[4] = h->tau_ff;
    }
  s.laws = pack_law_memory(inputs);
  if (sensors) {
    s.sensors = book->sensor_streams(t);
    const std::vector<double> snap = sensors->save();
    s.sensors.insert(s.sensors.end(), snap.begin(), snap.end());
  }
  return s;
}

SimulationState Simulation::state() const {
  const Impl& m = *impl_;
  IntegratorState x = m.now("state");
  SimulationState s = m.state_at(x.t);
  s.integrator = std::move(x);
  return s;
}

IntegratorState Simulation::integrator_state() {
  Impl& m = *impl_;
  m.require_running("integrator_state");
  m.bring_inputs_up_to_date();
  return m.now("integrator_state");
}

EquationsOfMotion& Simulation::equations() {
  RFEM_CHECK_ARGUMENT(impl_->eq != nullptr, "the simulation failed before its equations were built");
  return *impl_->eq;
}

SensorBank* Simulation::sensors() { return impl_->sensors.get(); }

RunResult Simulation::finish(std::optional<RunStatus> status) {
  Impl& m = *impl_;
  if (m.result) return *m.result;
  RunOutcome r;
  r.status = status ? *status : m.status;
  if (r.status.kind == RunStatus::Kind::Running)
    r.status = time() >= m.o.t_end ? RunStatus::completed() : RunStatus::interrupted(0);
  if (r.status.kind == RunStatus::Kind::Completed && time() < m.o.t_end) r.status = RunStatus::interrupted(0);
  r.t_reached = m.stepper ? m.stepper->t_reached() : 0.0;
  r.stats = m.stepper ? m.stepper->stats() : IntegratorStats{};
  m.status = r.status;
  m.result = m.book->end(r);
  if (m.file) {
    for (const Impl::PendingTable& t : m.tables)
      m.file->write_table("run/" + t.name, t.table, t.columns, t.units, t.description);
    m.file->close();
    write_views(m.cs, *m.model, m.opts.output, m.opts.warn);
  }
  return *m.result;
}

bool Simulation::finished() const { return impl_->result.has_value(); }
RunStatus Simulation::status() const { return impl_->status; }
const std::string& Simulation::output() const { return impl_->opts.output; }

void Simulation::record_table(const std::string& name, const Table& table, const std::vector<std::string>& columns,
                              const std::vector<std::string>& units, const std::string& description) {
  Impl& m = *impl_;
  m.require_running("record_table");
  RFEM_CHECK_ARGUMENT_SIZE(table.data.size(), table.rows * table.cols, "table");
  RFEM_CHECK_ARGUMENT_SIZE(columns.size(), table.cols, "columns");
  m.tables.push_back({name, table, columns, units, description});
}

}  // namespace rfem
