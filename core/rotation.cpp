#include "core/rotation.hpp"

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
// Generator of rotations about axis a: ∂Rot_a(φ)/∂φ = Rot_a(φ) G_a.
Mat3 generator(int a) {
  Mat3 G = Mat3::Zero();
  const int b = (a + 1) % 3, c = (a + 2) % 3;
  G(c, b) = 1.0;
  G(b, c) = -1.0;
  return G;
}
}  // namespace

void deformation_transform(const Vec6& q, DeformationTransform& out) {
  const Mat3 F[3] = {rot_x(q[3]), rot_y(q[4]), rot_z(q[5])};
  static const Mat3 G[3] = {generator(0), generator(1), generator(2)};
  // Factor a differentiated k times is F_a G_a^k (rotations about one axis commute with G_a).
  auto factor = [&](int a, int k) -> Mat3 {
    Mat3 f = F[a];
    for (int i = 0; i < k; ++i) f = f * G[a];
    return f;
  };
  const Mat3 R = F[0] * F[1] * F[2];
  out.D = homogeneous(R, q.head<3>());
  for (int j = 0; j < 3; ++j) {
    out.dD[j].setZero();
    out.dD[j](j, 3) = 1.0;
  }
  for (int a = 0; a < 3; ++a) {
    int k[3] = {0, 0, 0};
    k[a] = 1;
    out.dR[a] = factor(0, k[0]) * factor(1, k[1]) * factor(2, k[2]);
    out.dD[3 + a].setZero();
    out.dD[3 + a].leftCols<3>() = out.dR[a];
  }
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) {
      int k[3] = {0, 0, 0};
      ++k[a];
      ++k[b];
      out.ddR[a][b] = factor(0, k[0]) * factor(1, k[1]) * factor(2, k[2]);
      out.ddR[b][a] = out.ddR[a][b];
    }
}

Mat34 d_dot(const DeformationTransform& d, const Vec6& v) {
  Mat34 r = Mat34::Zero();
  for (int j = 0; j < 6; ++j) r += d.dD[j] * v[j];
  return r;
}

Mat34 d_ddot(const DeformationTransform& d, const Vec6& v, const Vec6& a) {
  Mat34 r = Mat34::Zero();
  for (int j = 0; j < 6; ++j) r += d.dD[j] * a[j];
  Mat3 quad = Mat3::Zero();
  for (int i = 0; i < 3; ++i)
    for (int l = 0; l < 3; ++l) quad += d.ddR[i][l] * (v[3 + i] * v[3 + l]);
  r.leftCols<3>() += quad;
  return r;
}

}  // namespace rfem
