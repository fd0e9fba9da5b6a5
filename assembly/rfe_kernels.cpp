#include "rfe_kernels.hpp"

namespace rfem {

namespace {
// Top rows of the homogeneous product X · [A; 0 0 0 0] for a 3×4 A (the derivative of a pose).
inline Mat34 lift(const Mat4& X, const Mat34& A) { return X.topLeftCorner<3, 3>() * A; }
}  // namespace

void rfe_pose(const Rfe& rfe, const LinkFrame& bk, const Vec6& q, const Vec6& v, const Vec6& a,
              RfePose& out, bool accelerations, bool second) {
  deformation_transform(q, out.d, accelerations || second);
  Mat4 P = out.d.D;
  P.topRightCorner<3, 1>() += rfe.centre;
  out.W = bk.B0 * P;
  out.R0 = bk.B0.topLeftCorner<3, 3>();
  if (!accelerations) return;
  const Mat34 Pd = d_dot(out.d, v), Pdd = d_ddot(out.d, v, a);
  out.Wdd = (bk.B0dd * P).topRows<3>() + 2.0 * lift(bk.B0d, Pd) + lift(bk.B0, Pdd);
}

void rfe_inertial_force(const Rfe& rfe, const RfePose& p, Vec6& eps, Mat4& Y) {
  const Mat34 F = p.R0.transpose() * p.Wdd;  // Ẅ seen in {r} axes
  // H = [J 0; 0 m] about the mass centre: ∂D/∂x_j H = m e_j e₄ᵀ, ∂D/∂φ_a H = [∂R/∂φ_a J, 0].
  const Mat3 J = rfe.H.topLeftCorner<3, 3>();
  for (int j = 0; j < 3; ++j) eps[j] = rfe.mass * F(j, 3);
  for (int a = 0; a < 3; ++a) eps[3 + a] = ((p.d.dR[a] * J).array() * F.leftCols<3>().array()).sum();
  Mat4 Wdd4 = Mat4::Zero();
  Wdd4.topRows<3>() = p.Wdd;
  Y = p.W * rfe.H * Wdd4.transpose();
}

void rfe_inertia(const Rfe& rfe, const LinkFrame& bk, const DeformationTransform& d, const Vec6& v,
                 const Vec6& a, const Vec3& p, Vec6& eps, Vec3& f, Vec3& n) {
  const Mat3 R0 = bk.B0.topLeftCorner<3, 3>();
  const Mat3& Om = bk.Omega.topLeftCorner<3, 3>();
  // Mass centre: a_c = Ω̈-part of {r} at p + Coriolis + relative acceleration.
  const Vec3 xd = R0 * v.head<3>(), xdd = R0 * a.head<3>();
  const Vec3 ac = bk.Omega_dd.topLeftCorner<3, 3>() * p + bk.Omega_dd.topRightCorner<3, 1>() + 2.0 * (Om * xd) + xdd;
  // Rotation R = R_A R_B R_C with axes g (in {r}): ω_rel = Σ g φ̇, ω̇_rel = Σ g φ̈ + (g_A φ̇_A) × (g_B φ̇_B)
  // + (g_A φ̇_A + g_B φ̇_B) × (g_C φ̇_C) with (A, B, C) = (φ2, φ3, φ1) (core/rotation.hpp).
  const Vec3 wA = d.axis[1] * v[4], wB = d.axis[2] * v[5], wC = d.axis[0] * v[3];
  const Vec3 wrel = wA + wB + wC;
  const Vec3 wdrel = d.axis[0] * a[3] + d.axis[1] * a[4] + d.axis[2] * a[5] + wA.cross(wB) + (wA + wB).cross(wC);
  const Vec3 wr = R0 * wrel;
  const Vec3 w = bk.w + wr;
  const Vec3 alpha = bk.wd + bk.w.cross(wr) + R0 * wdrel;
  // Euler's equations in the rfe's axes (Rw its rotation in the base frame, Ic its central inertia
  // there): τ = Rw (Ic α' + ω' × Ic ω') with α' = Rwᵀ α, ω' = Rwᵀ ω — no rotated inertia tensor.
  const Mat3 J = rfe.H.topLeftCorner<3, 3>();
  const Mat3 R = d.D.topLeftCorner<3, 3>(), Rw = R0 * R;
  const Mat3 Ic = J.trace() * Mat3::Identity() - J;
  const Vec3 wb = Rw.transpose() * w, Iw = Ic * wb;
  const Vec3 taur = R * (Ic * (Rw.transpose() * alpha) + wb.cross(Iw));  // τ in {r} axes
  const Vec3 tau = R0 * taur;
  f = rfe.mass * ac;
  n = p.cross(f) + tau;
  eps.head<3>() = R0.transpose() * f;
  for (int k = 0; k < 3; ++k) eps[3 + k] = d.axis[k].dot(taur);
}

void rfe_gravity_force(const Rfe& rfe, const RfePose& p, double g, Vec6& f, Vec4& s) {
  f.setZero();
  f.head<3>() = g * rfe.mass * p.R0.row(2).transpose();
  s = p.W * rfe.H.col(3);
}

void rfe_mass_blocks(const Rfe& rfe, const RfePose& p, const std::vector<Mat4>& Xi, const std::vector<int>& ancestors,
                     Mat6& Mkk, MatX& border, Mat4& G) {
  const Mat3 J = rfe.H.topLeftCorner<3, 3>();
  const Mat3 R = p.d.D.topLeftCorner<3, 3>();
  const Mat3 Ic = R * (J.trace() * Mat3::Identity() - J) * R.transpose();  // central inertia in {r}
  Eigen::Matrix<double, 3, 3> IcG;  // I_c g_a
  for (int a = 0; a < 3; ++a) IcG.col(a) = Ic * p.d.axis[a];
  Mkk.setZero();
  Mkk.topLeftCorner<3, 3>().diagonal().setConstant(rfe.mass);
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) Mkk(3 + a, 3 + b) = Mkk(3 + b, 3 + a) = p.d.axis[a].dot(IcG.col(b));
  const int m = static_cast<int>(ancestors.size());
  border.resize(m, 6);
  const Vec4 ph = p.W.col(3);
  for (int j = 0; j < m; ++j) {
    const Mat4& X = Xi[ancestors[j]];
    const Vec3 vj = X.topRows<3>() * ph;                               // velocity of the mass centre
    const Vec3 wj(X(2, 1), X(0, 2), X(1, 0));                           // angular velocity (world)
    border.block<1, 3>(j, 0) = rfe.mass * (p.R0.transpose() * vj).transpose();
    border.block<1, 3>(j, 3) = (p.R0.transpose() * wj).transpose() * IcG;
  }
  const Mat3 RJ = p.R0 * R;
  G.topLeftCorner<3, 3>() = RJ * J * RJ.transpose() + rfe.mass * ph.head<3>() * ph.head<3>().transpose();
  G.topRightCorner<3, 1>() = rfe.mass * ph.head<3>();
  G.bottomLeftCorner<1, 3>() = rfe.mass * ph.head<3>().transpose();
  G(3, 3) = rfe.mass;
}

void rfe_gravity_border(const Rfe& rfe, const RfePose& p, const std::vector<Mat4>& Xi,
                        const std::vector<int>& ancestors, double g, MatX& border) {
  const int m = static_cast<int>(ancestors.size());
  for (int j = 0; j < m; ++j)
    for (int l = 0; l < 3; ++l)
      border(j, l) += g * rfe.mass * Xi[ancestors[j]].block<1, 3>(2, 0).dot(p.R0.col(l));
}

Mat6 rfe_inertial_stiffness(const Rfe& rfe, const RfePose& p, const LinkFrame& bk) {
  // ε_j = tr(R0 ∂D_j H Ẅᵀ) with Ẅ = B̈0 P; differentiate both factors in q_l.
  const Mat34 F = p.R0.transpose() * p.Wdd;
  const Mat3 B0dd_R = p.R0.transpose() * bk.B0dd.topLeftCorner<3, 3>();
  Mat6 K;
  for (int j = 0; j < 6; ++j)
    for (int l = 0; l < 6; ++l) {
      double v = trace_AHBt(p.d.dD[j], rfe.H, B0dd_R * p.d.dD[l]);
      if (j >= 3 && l >= 3) {
        Mat34 dd = Mat34::Zero();
        dd.leftCols<3>() = p.d.ddR[j - 3][l - 3];
        v += trace_AHBt(dd, rfe.H, F);
      }
      K(j, l) = v;
    }
  return 0.5 * (K + K.transpose());
}

namespace {
// Top rows of Ẇ = Ḃ0 P + B0 Ṗ with P = C D.
Mat34 rfe_velocity(const Rfe& rfe, const RfePose& p, const LinkFrame& bk, const Vec6& v) {
  Mat4 P = p.d.D;
  P.topRightCorner<3, 1>() += rfe.centre;
  return (bk.B0d * P).topRows<3>() + lift(bk.B0, d_dot(p.d, v));
}
}  // namespace

double rfe_kinetic_energy(const Rfe& rfe, const RfePose& p, const LinkFrame& bk, const Vec6& v) {
  const Mat34 Wd = rfe_velocity(rfe, p, bk, v);
  return 0.5 * trace_AHBt(Wd, rfe.H, Wd);
}

void rfe_momentum_moments(const Rfe& rfe, const RfePose& p, const LinkFrame& bk, const Vec6& v, Vec3& lin,
                          Mat3& A) {
  const Mat34 Wd = rfe_velocity(rfe, p, bk, v);
  const Mat34 WH = p.W.topRows<3>() * rfe.H;
  lin = Wd * rfe.H.col(3);
  A = WH * Wd.transpose();
}

}  // namespace rfem
