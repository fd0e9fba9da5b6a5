#pragma once
// The rfe deformation transform D(q) = [R(φ) x; 0 1] [2.4] with its first and second partial
// derivatives in the six rfe coordinates q = [x1 x2 x3 φ1 φ2 φ3] (φ1 about the link axis x).
// R = RotY(φ2) RotZ(φ3) RotX(φ1): the paper's R = Rot1(φ1) Rot2(φ2) Rot3(φ3) with its link axis
// (3) mapped to our x, so torsion is the innermost rotation, about the rfe's own axis. (With the
// torsion outermost, turning a bent rfe about the axis of {r} would swing its attachment points
// against the stiff shear springs and tilt its large bending inertia into the torsion row.)
#include "types.hpp"

namespace rfem {

Mat3 rot_x(double a);
Mat3 rot_y(double a);
Mat3 rot_z(double a);
/// Rotation from roll-pitch-yaw angles, R = RotZ(yaw) RotY(pitch) RotX(roll) (used for mounts).
Mat3 rot_rpy(const Vec3& rpy);

/// D and its derivatives at one configuration. Derivatives are stored as their top three rows
/// (the bottom row of any derivative of a homogeneous transform is zero).
struct DeformationTransform {
  Mat4 D;
  std::array<Mat34, 6> dD;          ///< ∂D/∂q_j
  std::array<std::array<Mat3, 3>, 3> ddR;  ///< ∂²R/∂φ_a∂φ_b (translations enter D linearly)
  std::array<Mat3, 3> dR;           ///< ∂R/∂φ_a
  std::array<Vec3, 3> axis;         ///< g_a with ∂R/∂φ_a = [g_a×] R (the rotation axes in {r})
};

/// R(φ) and ∂R/∂φ of one rfe: all the sde forces need (kept per rfe during a residual evaluation).
struct RfeRotation {
  Mat3 R;
  std::array<Mat3, 3> dR;
};
RfeRotation rfe_rotation(const DeformationTransform& d);

/// Evaluates D(q), ∂D/∂q and, if `second`, ∂²R/∂φ² for one rfe (left unset otherwise).
void deformation_transform(const Vec6& q, DeformationTransform& out, bool second = true);

/// Ḋ = Σ ∂D/∂q_j q̇_j and D̈ = Σ ∂D/∂q_j q̈_j + Σ ∂²D/∂q_j∂q_l q̇_j q̇_l (top rows).
Mat34 d_dot(const DeformationTransform& d, const Vec6& v);
Mat34 d_ddot(const DeformationTransform& d, const Vec6& v, const Vec6& a);

}  // namespace rfem
