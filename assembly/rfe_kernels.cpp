#include "assembly/rfe_kernels.hpp"

namespace rfem {

namespace {
// Top rows of the homogeneous product X · [A; 0 0 0 0] for a 3×4 A (the derivative of a pose).
inline Mat34 lift(const Mat4& X, const Mat34& A) { return X.topLeftCorner<3, 3>() * A; }
}  // namespace

void rfe_pose(const Rfe& rfe, const BaseKinematics& bk, const Vec6& q, const Vec6& v, const Vec6& a,
              RfePose& out) {
  deformation_transform(q, out.d);
  Mat4 P = out.d.D;
  P.topRightCorner<3, 1>() += rfe.centre;
  out.W = bk.B0 * P;
  out.R0 = bk.B0.topLeftCorner<3, 3>();
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

void rfe_gravity_force(const Rfe& rfe, const RfePose& p, double g, Vec6& f, Vec4& s) {
  f.setZero();
  f.head<3>() = g * rfe.mass * p.R0.row(2).transpose();
  s = p.W * rfe.H.col(3);
}

void rfe_mass_blocks(const Rfe& rfe, const RfePose& p, const BaseKinematics& bk, Mat6& Mkk,
                     MatX& border, Mat4& G) {
  // H = [J 0; 0 m]: translations carry m I, rotations tr(∂R_a J ∂R_bᵀ), no coupling between them.
  Mkk.setZero();
  Mkk.topLeftCorner<3, 3>().diagonal().setConstant(rfe.mass);
  const Mat3 J = rfe.H.topLeftCorner<3, 3>();
  for (int a = 0; a < 3; ++a) {
    const Mat3 dRJ = p.d.dR[a] * J;
    for (int b = a; b < 3; ++b) Mkk(3 + a, 3 + b) = Mkk(3 + b, 3 + a) = (dRJ.array() * p.d.dR[b].array()).sum();
  }
  const Mat4 WH = p.W * rfe.H;
  const int m = static_cast<int>(bk.Xi.size());
  border.resize(m, 6);
  std::array<Mat34, 6> dW;
  for (int l = 0; l < 6; ++l) dW[l] = p.R0 * p.d.dD[l];
  for (int j = 0; j < m; ++j) {
    const Mat34 XWH = (bk.Xi[j] * WH).topRows<3>();
    for (int l = 0; l < 6; ++l) border(j, l) = (XWH.array() * dW[l].array()).sum();
  }
  G = WH * p.W.transpose();
}

void rfe_gravity_border(const Rfe& rfe, const RfePose& p, const BaseKinematics& bk, double g,
                        MatX& border) {
  const int m = static_cast<int>(bk.Xi.size());
  for (int j = 0; j < m; ++j)
    for (int l = 0; l < 3; ++l)
      border(j, l) += g * rfe.mass * bk.Xi[j].block<1, 3>(2, 0).dot(p.R0.col(l));
}

Mat6 rfe_inertial_stiffness(const Rfe& rfe, const RfePose& p, const BaseKinematics& bk) {
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

double rfe_kinetic_energy(const Rfe& rfe, const RfePose& p, const BaseKinematics& bk, const Vec6& v) {
  Mat4 P = p.d.D;
  P.topRightCorner<3, 1>() += rfe.centre;
  const Mat34 Wd = (bk.B0d * P).topRows<3>() + lift(bk.B0, d_dot(p.d, v));
  return 0.5 * trace_AHBt(Wd, rfe.H, Wd);
}

}  // namespace rfem
