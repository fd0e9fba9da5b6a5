#pragma once
// Time integration with SUNDIALS IDA of  q' = v,  M(q) v' + h(q, v) + f_el + f_g + f_d = τ
// (FORMULATION.md §5) over the unknown coordinates: the 6n rfe coordinates and the joints under
// force input. Joints under kinematic input follow their laws; their torques come out of the base
// rows (inverse dynamics). Two extra states integrate the dissipated energy and the input work.
// Our own IDA linear solver factorises S = c_j² M + c_j C + K on the bordered pattern with CHOLMOD
// and solves the 2N Newton system exactly for that (symmetric, approximate) Jacobian.
#include <atomic>
#include <functional>
#include <string>

#include "assembly/assemble.hpp"
#include "solvers/inputs.hpp"

namespace rfem {

struct IntegratorOptions {
  double t_end = 1.0;       ///< [s]
  double output_dt = 0.01;  ///< output interval [s]
  double rtol = 1e-6;
  double atol = 1e-8;            ///< absolute tolerance on coordinates [m, rad]
  /// Absolute tolerance on velocities [m/s, rad/s]. Undamped stiff sde modes (the joint turning
  /// against the first sde, ω ∝ n²) carry velocities far above their tiny displacements; an atol
  /// on velocities as small as on coordinates would force IDA to resolve them.
  double atol_velocity = 1e-5;
  double atol_energy = 1e-6;     ///< on the dissipated-energy and input-work integrals [J]
  double max_step = 0.0;    ///< 0: IDA's default (no limit)
  long max_steps = 20000;   ///< internal steps per output interval before giving up
  /// Highest BDF order. BDF orders above 2 are not A-stable: the undamped axial and shear sde
  /// modes (ω ~ 1e3–1e5 rad/s) would force tiny steps. BDF2 steps over them.
  int max_order = 2;
  ForceTerms forces;  ///< all on for physics; tests switch velocity products off
};

/// One output step: full coordinates, the torque of every joint (applied or required) and energies.
struct OutputSample {
  double t = 0.0;
  VecX q, v, a;   ///< full coordinates (flexible first, base last)
  VecX tau;       ///< joint torques/forces [N m or N], applied (force input) or required (kinematic)
  Energies energy;
  double dissipated = 0.0, input_work = 0.0;  ///< integrals since t = 0 [J]
  long steps = 0;        ///< IDA steps taken so far (for progress reports)
  double last_step = 0;  ///< IDA's last step size [s]
};

struct IntegratorStats {
  long steps = 0, residual_evals = 0, factorizations = 0, newton_iters = 0, newton_fails = 0, error_test_fails = 0;
  double last_step = 0.0;
};

struct RunOutcome {
  bool completed = false;
  std::string status;  ///< "completed", "interrupted (signal N)" or "failed: …"
  double t_reached = 0.0;
  IntegratorStats stats;
};

/// Integrates from t = 0 (rfes undeformed and at rest) to t_end, calling `sink` at t = 0 and every
/// output_dt. `stop` (may be null) is polled: non-zero interrupts the run cleanly.
/// With no unknowns (rigid manipulator, all joints prescribed) it evaluates inverse dynamics only.
RunOutcome integrate(const Model& model, const std::vector<JointInput>& inputs, const IntegratorOptions& opts,
                     const std::function<void(const OutputSample&)>& sink, const std::atomic<int>* stop = nullptr);

}  // namespace rfem
