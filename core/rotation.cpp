#include "rotation.hpp"

#include <cmath>

namespace rfem {

Mat3 rot_x(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 R;
  R << 1, 0, 0, 0, c, -s, 0, s, c;
  return R;
}
Mat3 rot_y(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 R;
  R << c, 0, s, 0, 1, 0, -s, 0, c;
  return R;
}
Mat3 rot_z(double a) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 R;
  R << c, -s, 0, s, c, 0, 0, 0, 1;
  return R;
}
Mat3 rot_rpy(const Vec3& rpy) { return rot_z(rpy[2]) * rot_y(rpy[1]) * rot_x(rpy[0]); }

namespace {
// [a×] M, column by column.
Mat3 cross_cols(const Vec3& a, const Mat3& M) {
  Mat3 r;
  for (int j = 0; j < 3; ++j) r.col(j) = a.cross(M.col(j));
  return r;
}
// [e_y×] M, the column-wise cross product with the y axis: (x, y, z) ↦ (z, 0, −x).
Mat3 cross_y(const Mat3& M) {
  Mat3 r;
  r.row(0) = M.row(2);
  r.row(1).setZero();
  r.row(2) = -M.row(0);
  return r;
}
}  // namespace

// With A = Ry Rz and g_a the rotation axes (∂R/∂φ_a = [g_a×] R: g_1 = R e_x, g_2 = e_y, g_3 = Ry e_z),
// every derivative is a column-wise cross product — no 3×3 products (this kernel runs once per rfe in
// every residual):
//   ∂R/∂φ1 = A ∂Rx = [0, R e_z, −R e_y],   ∂²R/∂φ1² = −[0, R e_y, R e_z],
//   ∂²R/∂φ2∂φ_a = [e_y×] ∂R/∂φ_a (φ2 outermost),   ∂²R/∂φ3∂φ1 = [g_3×] ∂R/∂φ1,   ∂²R/∂φ3² = [g_3×]² R.
void deformation_transform(const Vec6& q, DeformationTransform& out, bool second) {
  const double c1 = std::cos(q[3]), s1 = std::sin(q[3]), c2 = std::cos(q[4]), s2 = std::sin(q[4]);
  const double c3 = std::cos(q[5]), s3 = std::sin(q[5]);
  // R = Ry(φ2) Rz(φ3) Rx(φ1): torsion innermost, about the rfe's own axis.
  const Vec3 A0(c2 * c3, s3, -s2 * c3), A1(-c2 * s3, c3, s2 * s3), A2(s2, 0.0, c2);
  Mat3 R;
  R.col(0) = A0;
  R.col(1) = c1 * A1 + s1 * A2;
  R.col(2) = c1 * A2 - s1 * A1;
  out.D = homogeneous(R, q.head<3>());
  Mat3& dR0 = out.dR[0];
  dR0.col(0).setZero();
  dR0.col(1) = R.col(2);
  dR0.col(2) = -R.col(1);
  out.dR[1] = cross_y(R);
  out.dR[2] = cross_cols(A2, R);
  for (int j = 0; j < 3; ++j) {
    out.dD[j].setZero();
    out.dD[j](j, 3) = 1.0;
    out.dD[3 + j].leftCols<3>() = out.dR[j];
    out.dD[3 + j].col(3).setZero();
  }
  out.axis[0] = A0;
  out.axis[1] = Vec3::UnitY();
  out.axis[2] = A2;
  if (!second) return;
  Mat3& dd00 = out.ddR[0][0];
  dd00.col(0).setZero();
  dd00.col(1) = -R.col(1);
  dd00.col(2) = -R.col(2);
  out.ddR[1][1] = cross_y(out.dR[1]);
  out.ddR[2][2] = cross_cols(A2, out.dR[2]);
  out.ddR[0][1] = out.ddR[1][0] = cross_y(dR0);
  out.ddR[0][2] = out.ddR[2][0] = cross_cols(A2, dR0);
  out.ddR[1][2] = out.ddR[2][1] = cross_y(out.dR[2]);
}

RfeRotation rfe_rotation(const DeformationTransform& d) { return {d.D.topLeftCorner<3, 3>(), d.dR}; }

Mat34 d_dot(const DeformationTransform& d, const Vec6& v) {
  Mat34 r;
  r.leftCols<3>() = d.dR[0] * v[3] + d.dR[1] * v[4] + d.dR[2] * v[5];
  r.col(3) = v.head<3>();
  return r;
}

Mat34 d_ddot(const DeformationTransform& d, const Vec6& v, const Vec6& a) {
  Mat34 r;
  Mat3 m = d.dR[0] * a[3] + d.dR[1] * a[4] + d.dR[2] * a[5];
  for (int i = 0; i < 3; ++i) {
    m += d.ddR[i][i] * (v[3 + i] * v[3 + i]);
    for (int l = i + 1; l < 3; ++l) m += d.ddR[i][l] * (2.0 * v[3 + i] * v[3 + l]);
  }
  r.leftCols<3>() = m;
  r.col(3) = a.head<3>();
  return r;
}

}  // namespace rfem
