#pragma once
// Per-sde kernel [3.12]–[3.17]. Attachment points in {r}: p = C D η = centre + x + R(φ) η.
// Relative displacement Δx = p_right − p_left (sde axes = link axes), rotation difference
// Δφ = φ_right − φ_left. V = ½ Δxᵀ diag(c) Δx + ½ Δφᵀ diag(k) Δφ; damping d = β c, β k.
// Coordinates are the 12 of [rfe left; rfe right]; rfe_0 (left = −1) enters with zeros.
#include "../core/link.hpp"
#include "../core/rotation.hpp"

namespace rfem {

struct SdeResult {
  Vec12 f;     ///< elastic + damping generalised force ∂V/∂q + ∂R/∂q̇
  double V = 0.0;    ///< elastic energy [J]
  double P_d = 0.0;  ///< dissipated power [W]
};

/// Forces, energy and dissipation of sde `e` (ql/vl ignored when e.left == −1).
void sde_forces(const Sde& e, const Vec3& centre_left, const Vec3& centre_right, double beta,
                const Vec6& ql, const Vec6& vl, const Vec6& qp, const Vec6& vp, SdeResult& out);
/// The same with both rfes' rotations already evaluated (the residual evaluates each rfe once).
void sde_forces(const Sde& e, const Vec3& centre_left, const Vec3& centre_right, double beta,
                const Vec6& ql, const Vec6& vl, const Vec6& qp, const Vec6& vp, const RfeRotation& rl,
                const RfeRotation& rp, SdeResult& out);

/// Stiffness K = ∂²V/∂q² (with the geometric term of the rotated attachment points) and damping
/// C = β (Jᵀ diag(c) J + rotational part): S += ck K + cd C, and K itself into *K if given.
void sde_matrix(const Sde& e, const Vec3& centre_left, const Vec3& centre_right, double beta,
                const Vec6& ql, const Vec6& qp, double ck, double cd, Mat12& S, Mat12* K = nullptr);

/// The stiffness K = ∂²V/∂q² (with the geometric term) and, if C is given, the damping
/// C = β Jᵀ c J + rotational part, each assigned (not added).
void sde_matrices(const Sde& e, const Vec3& centre_left, const Vec3& centre_right, double beta, const Vec6& ql,
                  const Vec6& qp, Mat12& K, Mat12* C);
/// The same from both rfes' deformation transforms (with second derivatives), evaluated once per
/// rfe by the caller, in 3×3 blocks: with A = [∂R/∂φ_a η] and J = [−I, −A_l, I, A_p],
/// Jᵀ c J = [c, c A_l, −c, −c A_p; ·, A_lᵀ c A_l, −A_lᵀ c, −A_lᵀ c A_p; ·, ·, c, c A_p; ·, ·, ·, A_pᵀ c A_p].
void sde_matrices(const Sde& e, const Vec3& centre_left, const Vec3& centre_right, double beta, const Vec6& ql,
                  const Vec6& qp, const DeformationTransform& dl, const DeformationTransform& dp, Mat12& K, Mat12* C);

}  // namespace rfem
