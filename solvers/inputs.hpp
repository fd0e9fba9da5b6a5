#pragma once
// Joint inputs: each base joint is either driven by a prescribed motion law q(t), q̇(t), q̈(t)
// (kinematic input; its torque comes out of inverse dynamics) or by an applied torque/force τ(t)
// (force input; its motion is unknown). Mixed freely in one run.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "../core/types.hpp"

namespace rfem {

struct MotionSample {
  double q = 0, qd = 0, qdd = 0;
};

class MotionLaw {
 public:
  virtual ~MotionLaw() = default;
  virtual MotionSample at(double t) const = 0;
  /// Times where the law is less smooth (a jump in a derivative): integrators end steps there.
  virtual std::vector<double> breakpoints() const { return {}; }
};

class TorqueLaw {
 public:
  virtual ~TorqueLaw() = default;
  /// τ(t) of an open-loop law; for a feedback law the torque on its reference trajectory.
  virtual double at(double t) const = 0;
  /// τ at time t and the joint's own coordinate q and rate v (feedback laws; others ignore q, v).
  virtual double at(double t, double /*q*/, double /*v*/) const { return at(t); }
  /// −∂τ/∂q and −∂τ/∂v: what a feedback law adds to the joint's stiffness and damping (Newton matrix).
  virtual double stiffness() const { return 0.0; }
  virtual double damping() const { return 0.0; }
  virtual std::vector<double> breakpoints() const { return {}; }
  /// A law a digital controller samples (sampled_law): its sample time [s]; 0 for a continuous law.
  virtual double sample_time() const { return 0.0; }
  /// At a sample time t with the joint's q, v there (the integrator calls it, its steps ending at
  /// every sample): the law computes its next output.
  virtual void sample(double /*t*/, double /*q*/, double /*v*/) {}
  /// What a law remembers between samples (a digital law: its last sample's time, the held value
  /// and the outputs still delayed), for a saved state; restore() takes it back. Empty: nothing.
  virtual std::vector<double> memory() const { return {}; }
  virtual void restore(const std::vector<double>& /*memory*/) {}
};

/// Kane's deployment law (the dimensionally consistent form, docs/formulation.md §3):
/// ψ(t) = ψ0 − (π α/(2T)) (t − (T/2π) sin(2πt/T)) for t ≤ T, then ψ0 − π α/2.
std::shared_ptr<MotionLaw> deployment_law(double psi0, double alpha, double T);
/// Kane's spin-up law: θ = θ0 + (Ω/T)(t²/2 + (T/2π)²(cos(2πt/T) − 1)) for t ≤ T, then θ0 + Ω(t − T/2).
std::shared_ptr<MotionLaw> spinup_law(double theta0, double Omega, double T);
/// q = q0 + ω t.
std::shared_ptr<MotionLaw> constant_rate_law(double q0, double rate);
/// Natural cubic spline through (t_i, q_i): continuous acceleration. Constant extrapolation of the
/// end values with zero rate outside the table is not done: t outside the table is an error.
std::shared_ptr<MotionLaw> tabulated_motion(std::vector<double> t, std::vector<double> q);

std::shared_ptr<TorqueLaw> constant_torque(double tau);
/// Piecewise-linear interpolation of (t_i, τ_i); held constant beyond the ends.
std::shared_ptr<TorqueLaw> tabulated_torque(std::vector<double> t, std::vector<double> tau);
/// Natural cubic spline through (t_i, τ_i): error O(Δt⁴) for smooth torques (the samples of an
/// earlier run); t outside the table is an error.
std::shared_ptr<TorqueLaw> spline_torque(std::vector<double> t, std::vector<double> tau);
/// Any callable τ(t), smooth except at the given times.
/// PD feedback on a reference motion with an optional feed-forward torque:
///   τ = τ_ff(t) + k_p (q_ref(t) − q) + k_d (q̇_ref(t) − q̇).
/// With the rigid manipulator's inverse dynamics of the references as τ_ff (computed torque) the
/// feedback only corrects what the link's flexibility adds. kp, kd ≥ 0; ff may be null.
std::shared_ptr<TorqueLaw> pd_law(std::shared_ptr<MotionLaw> reference, double kp, double kd,
                                  std::shared_ptr<TorqueLaw> feedforward);
/// `law` run as a digital controller: evaluated at the joint's state at t_k = k·sample_time and held
/// (zero-order hold) from t_{k+delay} until the next value takes effect; before that it holds the
/// value of t = 0 (the controller was at rest before the run). A held value does not depend on the
/// joint's state between samples (no stiffness or damping of its own).
std::shared_ptr<TorqueLaw> sampled_law(std::shared_ptr<TorqueLaw> law, double sample_time, int delay);
std::shared_ptr<TorqueLaw> torque_function(std::function<double(double)> f, std::vector<double> breakpoints = {});

/// Reads a two-column CSV (time, value), '#' comments and one optional header line allowed.
/// Throws std::runtime_error naming the file and line.
void read_csv_series(const std::string& path, std::vector<double>& t, std::vector<double>& v);

struct JointInput {
  std::shared_ptr<MotionLaw> motion;  ///< set: kinematic input
  std::shared_ptr<TorqueLaw> torque;  ///< set: force input (initial value and rate from q0, v0)
  double q0 = 0.0, v0 = 0.0;
  bool prescribed() const { return static_cast<bool>(motion); }
  std::vector<double> breakpoints() const { return motion ? motion->breakpoints() : torque->breakpoints(); }
};

/// What the joints' laws remember (TorqueLaw::memory), as one vector: per joint its count, then its
/// values (a prescribed joint: 0); empty when no law remembers anything.
std::vector<double> pack_law_memory(const std::vector<JointInput>& inputs);
/// Gives every law its memory back; std::invalid_argument for memory of other joints or laws.
void restore_law_memory(const std::vector<JointInput>& inputs, const std::vector<double>& memory);

}  // namespace rfem
