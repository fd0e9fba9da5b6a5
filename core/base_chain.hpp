#pragma once
// The base: a serial chain of m joints with Craig's modified Denavit–Hartenberg parameters [2.1]
// A_i(q_i) = RotX(α_{i−1}) TransX(a_{i−1}) RotZ(θ_i) TransZ(d_i), θ_i = q_i + θ_i0 (revolute)
// or d_i = q_i + d_i0 (prismatic), and the rigid inertia of every base link.
#include <string>
#include <vector>

#include "core/joint_drive.hpp"
#include "core/types.hpp"

namespace rfem {

enum class JointType { Revolute, Prismatic };

struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  double alpha = 0.0;  ///< α_{i−1} [rad]
  double a = 0.0;      ///< a_{i−1} [m]
  double theta = 0.0;  ///< θ_i0 [rad]
  double d = 0.0;      ///< d_i0 [m]
  Mat4 H = Mat4::Zero();  ///< pseudo-inertia of base link i in its own frame
  JointDrive drive;       ///< rotor/gear inertia, damping, friction of the joint (none by default)
  double mass() const { return H(3, 3); }
};

/// A_i(q) for joint i.
Mat4 joint_transform(const Joint& j, double q);
/// The constant 4×4 generator Ĝ with ∂A_i/∂q = A_i Ĝ (rotation or translation along z).
Mat4 joint_generator(const Joint& j);

}  // namespace rfem
