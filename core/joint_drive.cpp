#include "joint_drive.hpp"

#include <cmath>

#include "check.hpp"

namespace rfem {

void JointDrive::check() const {
  require_non_negative("drive inertia", inertia);
  require_non_negative("drive damping", damping);
  require_non_negative("drive friction", friction);
  require_positive("drive friction_velocity", friction_velocity);
}

double JointDrive::dissipative_force(double v) const {
  return damping * v + (friction != 0.0 ? friction * std::tanh(v / friction_velocity) : 0.0);
}

double JointDrive::damping_derivative(double v) const {
  if (friction == 0.0) return damping;
  const double c = std::cosh(v / friction_velocity);
  return damping + friction / (friction_velocity * c * c);  // sech² → 0 far from v = 0, no overflow
}

}  // namespace rfem
