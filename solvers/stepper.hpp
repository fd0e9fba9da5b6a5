#pragma once
// One interface for everything that advances a run in time (studies/simulation.hpp drives it):
// ESDIRK (solvers/esdirk.cpp), IDA's BDF (solvers/bdf.cpp) and, for a model without unknowns,
// inverse dynamics at the outputs (solvers/integrator.cpp). A run is start() then advance(t_end); a
// caller that steps calls advance(t) as often as it likes, each call ending exactly at t, the
// outputs on the run's grid (output_time) delivered to the emitter as the steps pass them.
#include <memory>

#include "integrator.hpp"

namespace rfem {

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
