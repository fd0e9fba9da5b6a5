#pragma once
// Joints: by default a serial chain of m joints (the base) with Craig's modified Denavit–Hartenberg parameters [2.1]
// A_i(q_i) = RotX(α_{i−1}) TransX(a_{i−1}) RotZ(θ_i) TransZ(d_i), θ_i = q_i + θ_i0 (revolute)
// or d_i = q_i + d_i0 (prismatic), and the rigid inertia of every base link. A joint may move
// about (along) another unit axis u of its DH frame instead of z:
// A_i = RotX(α) TransX(a) RotZ(θ_i0) TransZ(d_i0) · Rot(u, q_i) (or Trans(u q_i)).
#include <limits>
#include <string>
#include <vector>

#include "joint_drive.hpp"
#include "mounting.hpp"
#include "types.hpp"

namespace rfem {

enum class JointType { Revolute, Prismatic };

/// What a joint is rated for (a URDF's <limit>): rfem does not enforce them — a run warns where
/// its solution leaves them (simulation/validity.hpp). Infinite: none.
struct JointLimits {
  double lower = -std::numeric_limits<double>::infinity();  ///< [rad or m]
  double upper = std::numeric_limits<double>::infinity();
  double effort = std::numeric_limits<double>::infinity();    ///< |τ| [N m or N]
  double velocity = std::numeric_limits<double>::infinity();  ///< |q̇| [rad/s or m/s]
};

struct Joint {
  std::string name;
  JointType type = JointType::Revolute;
  double alpha = 0.0;  ///< α_{i−1} [rad]
  double a = 0.0;      ///< a_{i−1} [m]
  double theta = 0.0;  ///< θ_i0 [rad]
  double d = 0.0;      ///< d_i0 [m]
  Vec3 axis = Vec3::UnitZ();  ///< unit joint axis in the joint's DH frame (z: Craig's joint)
  Mat4 H = Mat4::Zero();  ///< pseudo-inertia of the body it moves (its link, a payload), in its own frame
  JointDrive drive;       ///< rotor/gear inertia, damping, friction of the joint (none by default)
  Mounting on;            ///< what it sits on (default: the previous joint, a serial chain)
  JointLimits limits;     ///< rated range, speed and effort (warned about, not enforced)
  double mass() const { return H(3, 3); }
};

/// A_i(q) for joint i.
Mat4 joint_transform(const Joint& j, double q);
/// The constant 4×4 generator Ĝ with ∂A_i/∂q = A_i Ĝ (rotation about or translation along the axis).
Mat4 joint_generator(const Joint& j);

/// A free-floating base (a spacecraft bus) as six joints of the chain: translations along x, y, z
/// of {0}, then yaw, pitch, roll (ZYX: the bus frame is Trans(x, y, z) RotZ(ψ) RotY(θ) RotX(φ)),
/// the bus body (pseudo-inertia H in its own frame) on the last. The angles are singular at
/// pitch = ±90° (yaw and roll axes align); `free_base_pitch_limit` is where runs stop.
std::vector<Joint> free_base_joints(const Mat4& H);
constexpr int free_base_dofs = 6;
constexpr int free_base_pitch = 4;  ///< index of the pitch joint among the six
constexpr double free_base_pitch_limit = 85.0 * 3.14159265358979323846 / 180.0;  ///< [rad]

}  // namespace rfem
