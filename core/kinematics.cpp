#include "core/kinematics.hpp"

namespace rfem {

void base_kinematics(const Model& model, const VecX& qb, const VecX& vb, const VecX& ab,
                     BaseKinematics& out) {
  const int m = model.m();
  out.W.resize(m);
  out.Xi.resize(m);
  out.Wd.resize(m);
  out.Wdd.resize(m);
  Mat4 W = Mat4::Identity();
  Mat4 Omega = Mat4::Zero();   // Σ_{j≤i} Ξ_j q̇_j
  Mat4 Alpha = Mat4::Zero();   // Σ_{j≤i} Ξ_j q̈_j + Σ_{j,l≤i} Ξ_min Ξ_max q̇_j q̇_l
  for (int i = 0; i < m; ++i) {
    const Joint& jt = model.joints[i];
    W = W * joint_transform(jt, qb[i]);
    out.W[i] = W;
    out.Xi[i] = W * joint_generator(jt) * W.inverse();
    // Adding joint i: new quadratic terms 2 Ξ_j Ξ_i q̇_j q̇_i (j < i) and Ξ_i² q̇_i².
    Alpha += out.Xi[i] * ab[i] + (2.0 * Omega + out.Xi[i] * vb[i]) * out.Xi[i] * vb[i];
    Omega += out.Xi[i] * vb[i];
    out.Wd[i] = Omega * W;
    out.Wdd[i] = Alpha * W;
  }
  const Mat4 Wm = m ? out.W.back() : Mat4::Identity();
  out.B0 = Wm * model.mount;
  out.B0d = Omega * out.B0;
  out.B0dd = Alpha * out.B0;
  out.Omega_dd = Alpha;
  out.Omega = Omega;
  out.w = Vec3(Omega(2, 1), Omega(0, 2), Omega(1, 0));
  out.wd = 0.5 * Vec3(Alpha(2, 1) - Alpha(1, 2), Alpha(0, 2) - Alpha(2, 0), Alpha(1, 0) - Alpha(0, 1));
}

}  // namespace rfem
