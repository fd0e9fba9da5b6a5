#pragma once
// The ESDIRK integrator (solvers/esdirk.cpp) as an object that keeps its state between calls: a
// run is start() then advance(t_end); a simulation that a caller steps (studies/simulation.hpp) calls
// advance(t) as often as it likes, each call's last step ending exactly at t, the step-size history
// carried over. Outputs on the run's grid (output_time) go to the emitter as the steps pass them.
#include <memory>

#include "rfem/solvers/integrator.hpp"

namespace rfem {

class EsdirkStepper {
 public:
  /// Shares the equations (the caller keeps them alive); throws std::invalid_argument for an
  /// unusable table.
  EsdirkStepper(EquationsOfMotion& eq, const IntegratorOptions& opts);
  ~EsdirkStepper();
  EsdirkStepper(EsdirkStepper&&) noexcept;
  EsdirkStepper& operator=(EsdirkStepper&&) = delete;
  EsdirkStepper(const EsdirkStepper&) = delete;
  EsdirkStepper& operator=(const EsdirkStepper&) = delete;

  /// The initial state (or the emitter's resume state; std::invalid_argument if it does not fit),
  /// the t = 0 output delivered. Returns a Running status, or how the start failed.
  RunStatus start(SampleEmitter& emit);
  /// Steps until the time is `until` (t ≤ until ≤ t_end), the last step ending exactly there, the
  /// outputs in between delivered. Running while until < t_end; Completed at t_end; or Failed,
  /// Interrupted (the equations' stop token).
  RunStatus advance(double until, SampleEmitter& emit);
  /// The inputs changed at the current time (a held torque, a new reference): the accelerations and
  /// powers there are evaluated again, so the next step starts from the right limit.
  void inputs_changed();

  double time() const;       ///< where the last step ended [s]
  double t_reached() const;  ///< the last output delivered [s]
  const IntegratorStats& stats() const;
  /// Everything needed to go on from here (a checkpoint, a saved state).
  IntegratorState state() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfem
