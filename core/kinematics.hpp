#pragma once
// Kinematics of the tree of nodes (core/model.hpp) for one evaluation: world poses W_i of every
// node's frame and their derivatives, and the motion of every link's frame {r}. With
// Ξ_j = W_j Ĝ_j W_j⁻¹ (depends on the coordinates of j's ancestors only), for every body i beyond j
//   ∂W_i/∂q_j = Ξ_j W_i,  ∂²W_i/∂q_j∂q_l = Ξ_j Ξ_l W_i  (j an ancestor of l, or j = l),
// so Ẇ = Ω W with Ω = Σ Ξ_j q̇_j, and Ẅ = (Σ Ξ_j q̈_j + Σ_jl Ξ_min Ξ_max q̇_j q̇_l) W over the path
// from the root (docs/formulation.md §3).
#include "model.hpp"

namespace rfem {

/// Motion of a link's frame {r}: B0 and its time derivatives; Ω = Ḃ0 B0⁻¹ (top-left [ω×]) and
/// Omega_dd = B̈0 B0⁻¹, whose top-left is [ω̇×] + [ω×]².
struct LinkFrame {
  Mat4 B0 = Mat4::Identity(), B0d = Mat4::Zero(), B0dd = Mat4::Zero();
  Mat4 Omega = Mat4::Zero(), Omega_dd = Mat4::Zero();
  Vec3 w = Vec3::Zero(), wd = Vec3::Zero();  ///< angular velocity and acceleration of {r} in {0}
};

struct BaseKinematics {
  std::vector<Mat4> W;        ///< pose of node i's frame
  std::vector<Mat4> Xi;       ///< Ξ_i
  std::vector<Mat4> Wd, Wdd;  ///< Ẇ_i, Ẅ_i
  std::vector<Mat4> Omega, Alpha;  ///< Ẇ_i W_i⁻¹ and Ẅ_i W_i⁻¹
  std::vector<LinkFrame> frame;    ///< per link
};

/// Evaluates the tree at full coordinates q, rates v and accelerations a (each of model.dof()).
void base_kinematics(const Model& model, const VecX& q, const VecX& v, const VecX& a, BaseKinematics& out);
/// The same with zero joint accelerations (no vector of the model's size needed).
void base_kinematics(const Model& model, const VecX& q, const VecX& v, BaseKinematics& out);
/// The same at rest (zero rates and accelerations): the poses.
void base_kinematics(const Model& model, const VecX& q, BaseKinematics& out);

}  // namespace rfem
