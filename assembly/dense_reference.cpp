#include "assembly/dense_reference.hpp"

#include "assembly/assemble.hpp"
#include "assembly/sde_kernels.hpp"
#include "core/kinematics.hpp"
#include "core/rotation.hpp"

namespace rfem {

namespace {

struct Body {
  Mat4 W, H;
  std::vector<Mat4> dW;  // ∂W/∂q_a for every coordinate a (zero where W does not depend on it)
  std::vector<std::vector<Mat4>> ddW;
};

std::vector<Body> bodies(const Model& model, const VecX& q, bool second) {
  const int n = model.n(), m = model.m(), N = model.dof();
  BaseKinematics bk;
  const VecX z = VecX::Zero(m);
  base_kinematics(model, q.tail(m), z, z, bk);
  std::vector<Body> out;
  auto alloc = [&](Body& b) {
    b.dW.assign(N, Mat4::Zero());
    if (second) b.ddW.assign(N, std::vector<Mat4>(N, Mat4::Zero()));
  };
  for (int i = 0; i < m; ++i) {
    Body b;
    alloc(b);
    b.W = bk.W[i];
    b.H = model.joints[i].H;
    for (int j = 0; j <= i; ++j) {
      b.dW[model.joint_index(j)] = bk.Xi[j] * b.W;
      if (second)
        for (int l = 0; l <= i; ++l)
          b.ddW[model.joint_index(j)][model.joint_index(l)] = bk.Xi[std::min(j, l)] * bk.Xi[std::max(j, l)] * b.W;
    }
    out.push_back(std::move(b));
  }
  for (int k = 0; k < n; ++k) {
    const Rfe& rfe = model.link.rfes[k];
    DeformationTransform d;
    deformation_transform(q.segment<6>(model.rfe_index(k)), d);
    Mat4 P = d.D;
    P.topRightCorner<3, 1>() += rfe.centre;
    Body b;
    alloc(b);
    b.W = bk.B0 * P;
    b.H = rfe.H;
    auto pad = [](const Mat34& A) {
      Mat4 X = Mat4::Zero();
      X.topRows<3>() = A;
      return X;
    };
    for (int l = 0; l < 6; ++l) b.dW[model.rfe_index(k) + l] = bk.B0 * pad(d.dD[l]);
    for (int j = 0; j < m; ++j) b.dW[model.joint_index(j)] = bk.Xi[j] * b.W;
    if (second) {
      for (int j = 0; j < m; ++j) {
        for (int l = 0; l < m; ++l)
          b.ddW[model.joint_index(j)][model.joint_index(l)] = bk.Xi[std::min(j, l)] * bk.Xi[std::max(j, l)] * b.W;
        for (int l = 0; l < 6; ++l)
          b.ddW[model.joint_index(j)][model.rfe_index(k) + l] = b.ddW[model.rfe_index(k) + l][model.joint_index(j)] = bk.Xi[j] * b.dW[model.rfe_index(k) + l];
      }
      for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) {
          Mat34 A = Mat34::Zero();
          A.leftCols<3>() = d.ddR[a][c];
          b.ddW[model.rfe_index(k) + 3 + a][model.rfe_index(k) + 3 + c] = bk.B0 * pad(A);
        }
    }
    out.push_back(std::move(b));
  }
  return out;
}

}  // namespace

MatX dense_mass_matrix(const Model& model, const VecX& q) {
  const int N = model.dof();
  MatX M = MatX::Zero(N, N);
  for (const Body& b : bodies(model, q, false))
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) M(i, j) += (b.dW[i] * b.H * b.dW[j].transpose()).trace();
  for (int j = 0; j < model.m(); ++j) M(model.joint_index(j), model.joint_index(j)) += model.joints[j].drive.inertia;
  return M;
}

MatX dense_stiffness(const Model& model, const VecX& q, bool gravity) {
  const int n = model.n(), N = model.dof();
  MatX K = MatX::Zero(N, N);
  if (gravity)
    for (const Body& b : bodies(model, q, true))
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) K(i, j) += model.gravity * (b.ddW[i][j] * b.H.col(3))[2];
  for (int e = 0; e < n; ++e) {
    const Sde& s = model.link.sdes[e];
    Mat12 S = Mat12::Zero();
    const Vec3 cl = e > 0 ? model.link.rfes[e - 1].centre : model.link.rfe0.centre;
    const Vec6 ql = left_coords(model, q, e);
    sde_matrix(s, cl, model.link.rfes[e].centre, 0.0, ql, q.segment<6>(model.rfe_index(e)), 1.0, 0.0, S);
    for (int a = 0; a < 12; ++a)
      for (int b = 0; b < 12; ++b) {
        const int ra = model.rfe_index(e - 1) + a, rb = model.rfe_index(e - 1) + b;
        if (ra >= 0 && rb >= 0) K(ra, rb) += S(a, b);
      }
  }
  return K;
}

MatX dense_damping(const Model& model, const VecX& q, const VecX& v) {
  const int n = model.n(), N = model.dof();
  MatX C = MatX::Zero(N, N);
  for (int e = 0; e < n; ++e) {
    Mat12 S = Mat12::Zero();
    const Vec3 cl = e > 0 ? model.link.rfes[e - 1].centre : model.link.rfe0.centre;
    const Vec6 ql = left_coords(model, q, e);
    sde_matrix(model.link.sdes[e], cl, model.link.rfes[e].centre, model.link.damping_beta, ql,
               q.segment<6>(model.rfe_index(e)), 0.0, 1.0, S);
    for (int a = 0; a < 12; ++a)
      for (int b = 0; b < 12; ++b) {
        const int ra = model.rfe_index(e - 1) + a, rb = model.rfe_index(e - 1) + b;
        if (ra >= 0 && rb >= 0) C(ra, rb) += S(a, b);
      }
  }
  for (int j = 0; j < model.m(); ++j)
    C(model.joint_index(j), model.joint_index(j)) += model.joints[j].drive.damping_derivative(v[model.joint_index(j)]);
  return C;
}

}  // namespace rfem
