#include "integrator.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "../core/check.hpp"
#include "esdirk_stepper.hpp"

namespace rfem {

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Rigid manipulator with every joint prescribed: nothing to integrate, inverse dynamics at each
// output; the input work by Simpson's rule on each output interval (error O(Δt⁵) per interval,
// below round-off of the balance for smooth laws; the trapezoidal rule left 1e-5 J of drift).
class InverseDynamics final : public Stepper {
 public:
  InverseDynamics(EquationsOfMotion& eq, const IntegratorOptions& opts) : eq_(eq), o_(opts), n_out_(output_count(opts)) {}
  RunStatus start(SampleEmitter& emit) override {
    RFEM_CHECK_ARGUMENT(!started_, "the stepper has started already");
    started_ = true;
    if (emit.resume()) throw std::invalid_argument("a run without unknowns (inverse dynamics) does not resume: run it again");
    return output(emit);
  }
  RunStatus advance(double until, SampleEmitter& emit) override {
    RFEM_CHECK_ARGUMENT(started_, "start() first");
    RFEM_CHECK_ARGUMENT(until >= t_ && until <= o_.t_end, "until must lie in [t, t_end]");
    while (k_ <= n_out_ && output_time(o_, k_) <= until)
      if (RunStatus s = output(emit); s.kind != RunStatus::Kind::Running) return s;
    t_ = until;
    return t_ >= o_.t_end ? RunStatus::completed() : RunStatus{};
  }
  void inputs_changed() override {}  // (the joints follow their laws: nothing is held)
  double time() const override { return t_; }
  double t_reached() const override { return t_reached_; }
  const IntegratorStats& stats() const override { return st_; }
  IntegratorState state() const override {
    throw std::logic_error("a run without unknowns (inverse dynamics) has no state to go on from: run it again");
  }
  bool has_state() const override { return false; }

 private:
  double power(double t) const {
    const OutputSample s = eq_.sample(t, nullptr, nullptr, nullptr, 0.0, 0.0);
    return s.tau.dot(eq_.model().joint_coords(s.v));
  }
  // Output k_ (then the next one's index).
  RunStatus output(SampleEmitter& emit) {
    const double t = output_time(o_, k_);
    if (eq_.stop_requested()) return RunStatus::interrupted(eq_.stop().signal());
    try {
      const double Pm = k_ > 0 ? power(0.5 * (t + last_t_)) : 0.0;
      OutputSample s = eq_.sample(t, nullptr, nullptr, nullptr, 0.0, 0.0);
      const double P = s.tau.dot(eq_.model().joint_coords(s.v));
      W_ += (last_P_ + 4.0 * Pm + P) * (t - last_t_) / 6.0;
      s.input_work = W_;
      last_t_ = t;
      last_P_ = P;
      if (!emit(s) || !emit.beat(t, 0)) return emit.failure();
    } catch (const std::exception& e) {
      return RunStatus::failed(e.what());
    }
    t_ = t_reached_ = t;
    ++k_;
    return RunStatus{};
  }
  EquationsOfMotion& eq_;
  const IntegratorOptions o_;
  const long n_out_;
  long k_ = 0;
  double W_ = 0.0, last_t_ = 0.0, last_P_ = 0.0, t_ = 0.0, t_reached_ = 0.0;
  IntegratorStats st_;
  bool started_ = false;
};

}  // namespace

SampleEmitter::SampleEmitter(const SampleSink& sink, const RunControl& control)
    : sink_(sink), control_(control), last_beat_(now_s()), last_checkpoint_(last_beat_) {}

bool SampleEmitter::checkpoint_due() const {
  return !failed() && control_.checkpoint && control_.checkpoint_interval > 0 &&
         now_s() - last_checkpoint_ >= control_.checkpoint_interval;
}

bool SampleEmitter::checkpoint(const std::function<IntegratorState()>& st) {
  if (failed()) return false;
  if (!checkpoint_due()) return true;
  IntegratorState x = st();
  return checkpoint(x);
}

bool SampleEmitter::checkpoint(IntegratorState& st) {
  if (failed()) return false;
  if (!control_.checkpoint) return true;
  try {
    control_.checkpoint(st);
  } catch (const std::exception& e) {
    error_ = e.what();
  } catch (...) {
    error_ = "the checkpoint threw an unknown exception";
  }
  last_checkpoint_ = now_s();  // (the interval counts from the end of the writing)
  return !failed();
}

namespace {
bool finite(const OutputSample& s) {
  const Energies& e = s.energy;
  return s.q.allFinite() && s.v.allFinite() && s.a.allFinite() && s.tau.allFinite() && std::isfinite(e.kinetic) &&
         std::isfinite(e.elastic) && std::isfinite(e.gravity) && std::isfinite(s.dissipated) && std::isfinite(s.input_work) &&
         s.momentum.linear.allFinite() && s.momentum.angular.allFinite();
}
}  // namespace

bool SampleEmitter::operator()(const OutputSample& s) {
  if (failed()) return false;
  if (!finite(s)) {  // NaN or inf never reaches a results file as if it were a result
    char buf[160];
    std::snprintf(buf, sizeof buf, "non-finite values (NaN or inf) in the outputs at t = %.6g s; check the inputs' values", s.t);
    error_ = buf;
    return false;
  }
  try {
    if (sink_) sink_(s);
  } catch (const std::exception& e) {
    error_ = e.what();
  } catch (...) {
    error_ = "the output sink threw an unknown exception";
  }
  return !failed();
}

bool SampleEmitter::beat(double t, long steps) {
  if (failed()) return false;
  if (!control_.heartbeat) return true;
  const double now = now_s();
  if (now - last_beat_ < control_.heartbeat_interval) return true;
  last_beat_ = now;
  try {
    control_.heartbeat(t, steps);
  } catch (const std::exception& e) {
    error_ = e.what();
  } catch (...) {
    error_ = "the heartbeat threw an unknown exception";
  }
  return !failed();
}

std::string at_start(const std::string& why) {
  return why.find("t = ") == std::string::npos ? why + " at the start (t = 0)" : why;
}

std::string integrator_name(IntegratorKind k) { return k == IntegratorKind::Bdf ? "bdf" : "esdirk"; }

bool parse_integrator(const std::string& name, IntegratorKind& k) {
  if (name == "esdirk") k = IntegratorKind::Esdirk;
  else if (name == "bdf") k = IntegratorKind::Bdf;
  else return false;
  return true;
}

long output_count(const IntegratorOptions& o) { return std::lround(std::ceil(o.t_end / o.output_dt - 1e-9)); }

double output_time(const IntegratorOptions& o, long k) { return std::min(o.t_end, k * o.output_dt); }

void check_options(const IntegratorOptions& o) {
  require_positive("t_end", o.t_end);
  require_positive("output_dt", o.output_dt);
  if (o.output_dt > o.t_end) throw std::invalid_argument("output_dt must not exceed t_end");
  if (!(o.t_end / o.output_dt <= kMaxOutputs))
    throw std::invalid_argument("t_end / output_dt = " + std::to_string(o.t_end / o.output_dt) +
                                " outputs is more than the 1e8 a results file can take: choose a larger output_dt");
  require_positive("rtol", o.rtol);
  require_positive("atol", o.atol);
  require_positive("atol_velocity", o.atol_velocity);
  require_positive("atol_energy", o.atol_energy);
  require_non_negative("max_step", o.max_step);
  require_non_negative("fixed_step", o.fixed_step);
  if (o.max_steps < 1) throw std::invalid_argument("max_steps must be at least 1");
  if (o.max_order < 1 || o.max_order > 5) throw std::invalid_argument("max_order must be 1 to 5");
  if (o.kind == IntegratorKind::Esdirk) check_esdirk_table(o.esdirk_table);
}

std::unique_ptr<Stepper> make_bdf_stepper(EquationsOfMotion& eq, const IntegratorOptions& opts);  // (solvers/bdf.cpp)

std::unique_ptr<Stepper> make_stepper(EquationsOfMotion& eq, const IntegratorOptions& opts) {
  check_options(opts);
  if (eq.unknowns() == 0) return std::make_unique<InverseDynamics>(eq, opts);
  if (opts.kind == IntegratorKind::Bdf) return make_bdf_stepper(eq, opts);
  return std::make_unique<EsdirkStepper>(eq, opts);
}

RunOutcome integrate(std::shared_ptr<const Model> model, std::vector<JointInput> inputs, const IntegratorOptions& opts,
                     const SampleSink& sink, const RunControl& control) {
  check_options(opts);
  EquationsOfMotion eq(std::move(model), std::move(inputs), opts.forces, control.stop, opts.linear_solver, opts.parallel,
                       opts.kind == IntegratorKind::Bdf);  // IDA's solve needs K on its own
  SampleEmitter emit(sink, control);
  RunOutcome out;
  std::unique_ptr<Stepper> stepper;
  try {
    stepper = make_stepper(eq, opts);
    out.status = stepper->start(emit);
    if (out.status.kind == RunStatus::Kind::Running) out.status = stepper->advance(opts.t_end, emit);
  } catch (const std::exception& e) {  // (the steppers report their own failures; this is what is left)
    out.status = RunStatus::failed(e.what());
  }
  if (stepper) {
    out.stats = stepper->stats();
    out.t_reached = stepper->t_reached();
  }
  return out;
}

RunOutcome integrate(const Model& model, const std::vector<JointInput>& inputs, const IntegratorOptions& opts,
                     const SampleSink& sink, const RunControl& control) {
  // Not owned: the caller keeps the model alive for the call, which keeps nothing afterwards.
  return integrate(std::shared_ptr<const Model>(&model, [](const Model*) {}), inputs, opts, sink, control);
}

RunEstimate estimate_run(std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs,
                         const IntegratorOptions& opts, bool time) {
  RFEM_CHECK_ARGUMENT(model != nullptr, "no model");
  // Peak RSS of `rfem run cases/kane_spinup.toml` grows by 1.92 KiB per rfe with ESDIRK5 and the
  // chain solver, checkpoints included (n = 20 000 → 100 000: 60 MB → 214 MB; docs/performance.md):
  // Newton blocks (0.58 kB), stage and state vectors (0.77 kB), model (0.3 kB), full coordinates;
  // by 4.15 KiB with BDF (IDA's history and a separate stiffness). ~22 MB is the program itself
  // (its libraries, the case, HDF5's caches: 24.0 MB at n = 1 000).
  const double per_rfe = opts.kind == IntegratorKind::Bdf ? 4.25e3 : 1.97e3;
  RunEstimate e;
  e.bytes = 22e6 + per_rfe * model->n();
  if (!time) return e;
  EquationsOfMotion eq(model, inputs, opts.forces, StopToken{}, opts.linear_solver, opts.parallel,
                       opts.kind == IntegratorKind::Bdf);
  if (eq.unknowns() == 0) return e;
  VecX q, v;
  eq.initial_state(q, v, false);
  VecX a = VecX::Zero(eq.unknowns()), r(eq.unknowns());
  using clock = std::chrono::steady_clock;
  double best = INFINITY;
  for (int k = 0; k < 3; ++k) {  // the fastest of three: the first one pays for page faults
    const auto t0 = clock::now();
    eq.residual(0.0, q.data(), v.data(), a.data(), r.data());
    best = std::min(best, std::chrono::duration<double>(clock::now() - t0).count());
  }
  e.residual_s = best;
  const auto t0 = clock::now();
  eq.setup_newton(0.0, q.data(), v.data(), 1e-3);
  e.newton_setup_s = std::chrono::duration<double>(clock::now() - t0).count();
  return e;
}

}  // namespace rfem
