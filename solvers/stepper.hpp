#pragma once
// One interface for everything that advances a run in time (simulation/simulation.hpp drives it):
// ESDIRK (solvers/esdirk.cpp), IDA's BDF (solvers/bdf.cpp) and, for a model without unknowns,
// inverse dynamics at the outputs (solvers/integrator.cpp). A run is start() then advance(t_end); a
// caller that steps calls advance(t) as often as it likes, each call ending exactly at t, the
// outputs on the run's grid (output_time) delivered to the emitter as the steps pass them.
#include <functional>
#include <memory>
#include <stdexcept>

#include "integrator.hpp"

namespace rfem {

/// A sample-and-hold the steps stop at: a digital law (TorqueLaw::sample_time, its joint's value
/// held between samples) or a caller's controller in the loop (studies/control_loop.cpp) — one
/// mechanism for both. sample(t) is called at t = k·period (k = next, next + 1, …) once the steps
/// reach t, after the outputs there; it returns whether it changed the inputs (the accelerations
/// and powers there are then evaluated again: the next step starts from the right limit). What it
/// throws ends the run failed with its words.
struct Sampler {
  double period = 0.0;  ///< [s]
  long next = 0;        ///< the next k
  /// It reads the state (a snapshot): inputs changed by earlier samplers at t are in force first.
  bool needs_state = false;
  std::function<bool(double t)> sample;
};

/// What a sampler threw, carried through the stepper unchanged (not a step's failure).
class SamplerFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  /// The initial state (or the emitter's resume state; std::invalid_argument if it does not fit),
  /// the t = 0 output delivered. Returns a Running status, or how the start failed.
  virtual RunStatus start(SampleEmitter& emit) = 0;
  /// Steps until the time is `until` (t ≤ until ≤ t_end), the last step ending exactly there, the
  /// outputs in between delivered. Running while until < t_end; Completed at t_end; or Failed,
  /// Interrupted (the equations' stop token).
  virtual RunStatus advance(double until, SampleEmitter& emit) = 0;
  /// The inputs changed at the current time (a held torque, a new reference): the accelerations and
  /// powers there are evaluated again, so the next step starts from the right limit.
  virtual void inputs_changed() = 0;
  /// Adds a sampler after the digital laws' (std::logic_error where the steps do not stop at
  /// samples: BDF, inverse dynamics).
  virtual void add_sampler(Sampler) {
    throw std::logic_error("sample-and-hold needs simulation.integrator = \"esdirk\" (its steps end at the samples)");
  }
  virtual double time() const = 0;       ///< where the last step ended [s]
  virtual double t_reached() const = 0;  ///< the last output delivered [s]
  virtual const IntegratorStats& stats() const = 0;
  /// Everything needed to go on from here (a checkpoint, a saved state). ESDIRK goes on from it bit
  /// for bit; IDA restarts there (its history is not kept: the same solution within the
  /// tolerances); inverse dynamics has none (std::logic_error).
  virtual IntegratorState state() const = 0;
  /// Whether state() gives one.
  virtual bool has_state() const { return true; }
};

/// The stepper of opts.kind on the equations (the caller keeps them alive): inverse dynamics if
/// they have no unknowns. std::invalid_argument for unusable options.
std::unique_ptr<Stepper> make_stepper(EquationsOfMotion& eq, const IntegratorOptions& opts);

}  // namespace rfem
