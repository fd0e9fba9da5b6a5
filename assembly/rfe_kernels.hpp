#pragma once
// Per-rfe kernels. World pose of rfe k: W_k = B0 C_k D_k(q_k) [2.5] with C_k = Trans(centre_k) and
// B0 the pose of its link's frame {r} (`LinkFrame`). Kinetic energy T_k = ½ tr(Ẇ H Ẇᵀ) [3.6]; the
// Lagrange term of coordinate j is ε_j = tr(∂W/∂q_j H Ẅᵀ) (docs/formulation.md §3), which gives M a + h in
// one pass without b-tensors. Rows of the nodes that move {r} (`ancestors`, core/kinematics.hpp) are
// returned as 4×4 "moment" matrices that the caller contracts with Ξ_j: ε_j = tr(Ξ_j Y),
// M_jl = tr(Ξ_j G Ξ_lᵀ), gravity g e₃ᵀ Ξ_j s.
#include "../core/kinematics.hpp"
#include "../core/rotation.hpp"

namespace rfem {

/// Everything about one rfe at one configuration that several kernels share.
struct RfePose {
  DeformationTransform d;
  Mat4 W;      ///< world pose
  Mat3 R0;     ///< rotation of {r} in {0}
  Mat34 Wdd;   ///< top rows of Ẅ
};

/// Pose, and Ẅ = B̈0 P + 2 Ḃ0 Ṗ + B0 P̈ with P = C D. Without `accelerations` only D (first
/// derivatives, and second ones if `second`), W and R0 are set: all the mass blocks need.
void rfe_pose(const Rfe& rfe, const LinkFrame& bk, const Vec6& q, const Vec6& v, const Vec6& a,
              RfePose& out, bool accelerations = true, bool second = false);

/// Inertial force ε (= M a + h) on the rfe's own coordinates, and Y = W H Ẅᵀ for the base rows.
void rfe_inertial_force(const Rfe& rfe, const RfePose& p, Vec6& eps, Mat4& Y);

/// The same inertial force by Kane's method (the residual's kernel: no second derivatives of R,
/// no 4×4 products): with the mass centre's acceleration a_c and the rfe's angular velocity ω and
/// acceleration α in {0}, the central inertia I = R_w (tr J − J) R_wᵀ and τ = I α + ω × I ω,
///   ε_x = m R0ᵀ a_c,   ε_φa = (R0 g_a) · τ,
/// and the wrench about the origin of {0} that the base rows need: f = m a_c, n = p × f + τ
/// (ε_bj = ω_j · n + t_j · f for joint j's unit twist (ω_j, t_j)). `d` needs no second derivatives.
void rfe_inertia(const Rfe& rfe, const LinkFrame& bk, const DeformationTransform& d, const Vec6& v,
                 const Vec6& a, const Vec3& p, Vec6& eps, Vec3& f, Vec3& n);

/// Gravity force ∂V_g/∂q_k (only the translations: the rfe's origin is its mass centre) and
/// s = W H e₄ (mass × homogeneous position of the mass centre) for the base rows.
void rfe_gravity_force(const Rfe& rfe, const RfePose& p, double g, Vec6& f, Vec4& s);

/// Mass blocks: M_kk (6×6), border M_bk (a row per ancestor node j: tr(Ξ_j W H ∂W/∂q_lᵀ)), G = W H Wᵀ.
/// With H = [J 0; 0 m] about the mass centre and ∂R/∂φ_a = [g_a×] R these are
///   M_kk = [m I, 0; 0, g_aᵀ I_c g_b],  border(j, x) = m R0ᵀ (Ξ_j p̂)₁₋₃,  border(j, φ_a) = ω_jᵀ I_c g_a,
/// with I_c = R (tr J − J) Rᵀ the rfe's central inertia in {r} axes, p̂ its homogeneous mass centre
/// in {0} and ω_j = R0ᵀ (the axis of Ξ_j) (FD-tested against the traces).
void rfe_mass_blocks(const Rfe& rfe, const RfePose& p, const std::vector<Mat4>& Xi, const std::vector<int>& ancestors,
                     Mat6& Mkk, MatX& border, Mat4& G);

/// Gravity stiffness border ∂²V_g/∂q_j∂q_k,l for the ancestor nodes j (the rfe's own block is
/// zero), added to `border` (a row per ancestor).
void rfe_gravity_border(const Rfe& rfe, const RfePose& p, const std::vector<Mat4>& Xi,
                        const std::vector<int>& ancestors, double g, MatX& border);

/// ∂ε_k/∂q_k at zero rfe velocity and acceleration: the centrifugal stiffness of a moving base
/// (used by modal analysis about a steady rotation), symmetrised.
Mat6 rfe_inertial_stiffness(const Rfe& rfe, const RfePose& p, const LinkFrame& bk);

/// Kinetic energy ½ tr(Ẇ H Ẇᵀ) with Ẇ = Ḃ0 P + B0 Ṗ.
double rfe_kinetic_energy(const Rfe& rfe, const RfePose& p, const LinkFrame& bk, const Vec6& v);
/// ∫ ẋ dm (rows 0–2 of col 3) and ∫ x ẋᵀ dm (top-left 3×3) of the rfe in {0}: W H Ẇᵀ with
/// column 3 replaced by Ẇ H e₄ (momentum.hpp turns them into linear and angular momentum).
void rfe_momentum_moments(const Rfe& rfe, const RfePose& p, const LinkFrame& bk, const Vec6& v, Vec3& lin,
                          Mat3& A);

}  // namespace rfem
