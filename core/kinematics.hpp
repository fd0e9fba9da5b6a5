#pragma once
// Base kinematics for one evaluation: world poses W_i of the base links and B0 of {r}, and their
// derivatives. With Ξ_j = W_j Ĝ_j W_j⁻¹ (depends on q_1..q_{j−1} only):
//   ∂W_i/∂q_j = Ξ_j W_i (j ≤ i),  ∂²W_i/∂q_j∂q_l = Ξ_min(j,l) Ξ_max(j,l) W_i,
// so Ẇ = Ω W with Ω = Σ Ξ_j q̇_j, and Ẅ = (Σ Ξ_j q̈_j + Σ_jl Ξ_min Ξ_max q̇_j q̇_l) W.
#include "core/model.hpp"

namespace rfem {

struct BaseKinematics {
  std::vector<Mat4> W;    ///< pose of base link i
  std::vector<Mat4> Xi;   ///< Ξ_j
  std::vector<Mat4> Wd, Wdd;  ///< Ẇ_i, Ẅ_i
  Mat4 B0, B0d, B0dd;     ///< pose of {r} and its first and second time derivatives
  Mat4 Omega_dd = Mat4::Zero();  ///< Ẅ W⁻¹ for the last link (applies to every rfe)
  /// Motion of {r} as a rigid body: angular velocity Ω and acceleration Ω̇ (in {0}); Ẇ W⁻¹ = Omega
  /// has the top-left [Ω×], and Ω̇ is the skew part of Omega_dd's top-left (Omega² adds a
  /// symmetric [Ω×]²).
  Mat4 Omega = Mat4::Zero();
  Vec3 w = Vec3::Zero(), wd = Vec3::Zero();
};

/// Evaluates base kinematics at joint values q_b, rates v_b and accelerations a_b.
void base_kinematics(const Model& model, const VecX& qb, const VecX& vb, const VecX& ab,
                     BaseKinematics& out);

}  // namespace rfem
