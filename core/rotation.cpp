#include "rfem/core/rotation.hpp"

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
// First and second derivatives of the elementary rotations, written out (no generator products).
Mat3 d_rot_x(double c, double s) { Mat3 R; R << 0, 0, 0, 0, -s, -c, 0, c, -s; return R; }
Mat3 d_rot_y(double c, double s) { Mat3 R; R << -s, 0, c, 0, 0, 0, -c, 0, -s; return R; }
Mat3 d_rot_z(double c, double s) { Mat3 R; R << -s, -c, 0, c, -s, 0, 0, 0, 0; return R; }
Mat3 dd_rot_x(double c, double s) { Mat3 R; R << 0, 0, 0, 0, -c, s, 0, -s, -c; return R; }
Mat3 dd_rot_y(double c, double s) { Mat3 R; R << -c, 0, -s, 0, 0, 0, s, 0, -c; return R; }
Mat3 dd_rot_z(double c, double s) { Mat3 R; R << -c, s, 0, -s, -c, 0, 0, 0, 0; return R; }
}  // namespace

void deformation_transform(const Vec6& q, DeformationTransform& out, bool second) {
  const double c1 = std::cos(q[3]), s1 = std::sin(q[3]), c2 = std::cos(q[4]), s2 = std::sin(q[4]);
  const double c3 = std::cos(q[5]), s3 = std::sin(q[5]);
  Mat3 Rx, Ry, Rz;
  Rx << 1, 0, 0, 0, c1, -s1, 0, s1, c1;
  Ry << c2, 0, s2, 0, 1, 0, -s2, 0, c2;
  Rz << c3, -s3, 0, s3, c3, 0, 0, 0, 1;
  const Mat3 dRx = d_rot_x(c1, s1), dRy = d_rot_y(c2, s2), dRz = d_rot_z(c3, s3);
  // R = Ry(φ2) Rz(φ3) Rx(φ1): torsion innermost, about the rfe's own axis.
  const Mat3 RyRz = Ry * Rz, RzRx = Rz * Rx;
  out.D = homogeneous(RyRz * Rx, q.head<3>());
  for (int j = 0; j < 3; ++j) {
    out.dD[j].setZero();
    out.dD[j](j, 3) = 1.0;
  }
  out.dR[0] = RyRz * dRx;
  out.dR[1] = dRy * RzRx;
  out.dR[2] = Ry * (dRz * Rx);
  for (int a = 0; a < 3; ++a) {
    out.dD[3 + a].setZero();
    out.dD[3 + a].leftCols<3>() = out.dR[a];
  }
  out.axis[0] = RyRz.col(0);
  out.axis[1] = Vec3::UnitY();
  out.axis[2] = Ry.col(2);
  if (!second) return;
  out.ddR[0][0] = RyRz * dd_rot_x(c1, s1);
  out.ddR[1][1] = dd_rot_y(c2, s2) * RzRx;
  out.ddR[2][2] = Ry * (dd_rot_z(c3, s3) * Rx);
  out.ddR[0][1] = out.ddR[1][0] = dRy * (Rz * dRx);
  out.ddR[0][2] = out.ddR[2][0] = Ry * (dRz * dRx);
  out.ddR[1][2] = out.ddR[2][1] = dRy * (dRz * Rx);
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
