#pragma once
// What a joint's drive adds to its generalised force: the reflected inertia of rotor
// and gearbox, viscous damping and Coulomb friction smoothed by tanh,
//   τ_drive(q̇, q̈) = J q̈ + c q̇ + F_c tanh(q̇ / v_s).
// The drive's kinetic energy is ½ J q̇², the power it dissipates c q̇² + F_c q̇ tanh(q̇ / v_s) ≥ 0.
// The regularisation replaces the friction law's jump at q̇ = 0 by a slope F_c / v_s: below
// |q̇| ≈ v_s a joint creeps instead of sticking (no stiction), above 3 v_s the force is within
// 0.5 % of F_c. Units follow the joint: rad and N m (revolute), m and N (prismatic).
namespace rfem {

struct JointDrive {
  double inertia = 0.0;            ///< J: rotor and gear inertia reflected to the joint [kg m² or kg]
  double damping = 0.0;            ///< c [N m s/rad or N s/m]
  double friction = 0.0;           ///< Coulomb level F_c [N m or N]
  double friction_velocity = 1e-3; ///< v_s of the tanh regularisation [rad/s or m/s], > 0

  bool active() const { return inertia != 0.0 || damping != 0.0 || friction != 0.0; }
  /// c q̇ + F_c tanh(q̇ / v_s): the dissipative part of τ_drive.
  double dissipative_force(double v) const;
  /// ∂(dissipative_force)/∂q̇ (the drive's entry of the damping matrix C).
  double damping_derivative(double v) const;
  /// Power dissipated at rate v [W]: v · dissipative_force(v).
  double power(double v) const { return v * dissipative_force(v); }
  /// d(power)/dq̇.
  double power_derivative(double v) const { return dissipative_force(v) + v * damping_derivative(v); }
  double kinetic_energy(double v) const { return 0.5 * inertia * v * v; }
  /// Throws std::invalid_argument unless inertia, damping, friction ≥ 0 and friction_velocity > 0
  /// (finite): the dissipated power is then never negative.
  void check() const;
};

}  // namespace rfem
