#include "dense_reference.hpp"

#include "../core/check.hpp"

#include "assemble.hpp"
#include "sde_kernels.hpp"
#include "../core/rotation.hpp"

namespace rfem {

namespace {

Mat4 pad(const Mat34& A) {
  Mat4 X = Mat4::Zero();
  X.topRows<3>() = A;
  return X;
}

// One factor of a body's pose W = F_1 F_2 … F_K: a constant transform, a joint A(q) (∂A/∂q = A Ĝ),
// or an rfe's D(q) [2.4] with its own derivatives (not the six one-coordinate nodes of the model:
// the reference does not share that representation).
struct Factor {
  Mat4 F;
  std::vector<std::pair<int, Mat4>> d;                  // (coordinate, ∂F)
  std::vector<std::tuple<int, int, Mat4>> dd;           // (i, j, ∂²F/∂q_i∂q_j), both orders
};

Factor constant(const Mat4& X) { return {X, {}, {}}; }

Factor joint_factor(const Joint& j, const VecX& q, int c, const Mat4* pre) {
  const Mat4 A = (pre ? *pre : Mat4::Identity()) * joint_transform(j, q[c]);
  const Mat4 G = joint_generator(j);
  return {A, {{c, A * G}}, {{c, c, A * G * G}}};
}

Factor rfe_factor(const VecX& q, int c) {
  DeformationTransform d;
  deformation_transform(q.segment<6>(c), d, true);
  Factor f{d.D, {}, {}};
  for (int l = 0; l < 6; ++l) f.d.push_back({c + l, pad(d.dD[l])});
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      Mat34 A = Mat34::Zero();
      A.leftCols<3>() = d.ddR[a][b];
      f.dd.push_back({c + 3 + a, c + 3 + b, pad(A)});
    }
  return f;
}

// The factors of node i's frame: its path from the root, a carrying rfe's six axes as one D.
std::vector<Factor> path_factors(const Model& model, const VecX& q, int i) {
  std::vector<Factor> out;
  if (i < 0) return out;
  for (int p : model.nodes[i].path) {
    const Node& nd = model.nodes[p];
    if (nd.joint >= 0) {
      out.push_back(joint_factor(nd.motion, q, nd.coord, nd.has_pre ? &nd.pre : nullptr));
    } else if (nd.coord == model.rfe_index(nd.link, nd.rfe)) {  // the first of the rfe's six axes
      const MountedLink& L = model.links[nd.link];
      out.push_back(constant(L.mount));
      out.push_back(constant(homogeneous(Mat3::Identity(), L.d.rfes[nd.rfe].centre)));
      out.push_back(rfe_factor(q, nd.coord));
    }
  }
  return out;
}

struct Body {
  Mat4 W, H;
  std::vector<Mat4> dW;  // ∂W/∂q_a for every coordinate a (zero where W does not depend on it)
  std::vector<std::vector<Mat4>> ddW;
};

// W and its derivatives by the product rule over the factors.
Body body(const std::vector<Factor>& fs, const Mat4& H, int N, bool second) {
  const int K = static_cast<int>(fs.size());
  std::vector<Mat4> pre(K + 1, Mat4::Identity()), suf(K + 1, Mat4::Identity());
  for (int f = 0; f < K; ++f) pre[f + 1] = pre[f] * fs[f].F;
  for (int f = K - 1; f >= 0; --f) suf[f] = fs[f].F * suf[f + 1];
  Body b;
  b.W = pre[K];
  b.H = H;
  b.dW.assign(N, Mat4::Zero());
  for (int f = 0; f < K; ++f)
    for (const auto& [i, dF] : fs[f].d) b.dW[i] += pre[f] * dF * suf[f + 1];
  if (!second) return b;
  b.ddW.assign(N, std::vector<Mat4>(N, Mat4::Zero()));
  for (int f = 0; f < K; ++f) {
    for (const auto& [i, j, ddF] : fs[f].dd) b.ddW[i][j] += pre[f] * ddF * suf[f + 1];
    Mat4 mid = Mat4::Identity();  // F_{f+1} … F_{g−1}
    for (int g = f + 1; g < K; ++g) {
      for (const auto& [i, dFi] : fs[f].d)
        for (const auto& [j, dFj] : fs[g].d) {
          const Mat4 t = pre[f] * dFi * mid * dFj * suf[g + 1];
          b.ddW[i][j] += t;
          b.ddW[j][i] += t;
        }
      mid = mid * fs[g].F;
    }
  }
  return b;
}

std::vector<Body> bodies(const Model& model, const VecX& q, bool second) {
  const int N = model.dof();
  std::vector<Body> out;
  for (size_t i = 0; i < model.nodes.size(); ++i) {  // rigid bodies: joints' and carrying rfes'
    const Node& nd = model.nodes[i];
    if (nd.joint < 0 && nd.coord != model.rfe_index(nd.link, nd.rfe) + 3) continue;  // an rfe's body: its φ1 axis (the last)
    out.push_back(body(path_factors(model, q, static_cast<int>(i)), nd.H, N, second));
  }
  for (size_t l = 0; l < model.links.size(); ++l) {
    const MountedLink& L = model.links[l];
    for (int k = 0; k < L.n(); ++k) {
      if (L.carries(k)) continue;
      std::vector<Factor> fs = path_factors(model, q, L.parent);
      fs.push_back(constant(L.mount));
      fs.push_back(constant(homogeneous(Mat3::Identity(), L.d.rfes[k].centre)));
      fs.push_back(rfe_factor(q, model.rfe_index(static_cast<int>(l), k)));
      out.push_back(body(fs, L.d.rfes[k].H, N, second));
    }
  }
  return out;
}

// Σ over every link's sdes of their 12×12 matrices (stiffness ck, damping cd) at their coordinates.
MatX sde_sum(const Model& model, const VecX& q, double ck, double cd) {
  const int N = model.dof();
  MatX K = MatX::Zero(N, N);
  for (size_t l = 0; l < model.links.size(); ++l) {
    const int li = static_cast<int>(l);
    const Discretisation& d = model.links[l].d;
    for (int e = 0; e < d.n(); ++e) {
      Mat12 S = Mat12::Zero();
      const Vec3 cl = e > 0 ? d.rfes[e - 1].centre : d.rfe0.centre;
      sde_matrix(d.sdes[e], cl, d.rfes[e].centre, d.damping_beta, left_coords(model, q, li, e), rfe_coords(model, q, li, e),
                 ck, cd, S);
      const int at[2] = {e > 0 ? model.rfe_index(li, e - 1) : -1, model.rfe_index(li, e)};
      for (int a = 0; a < 12; ++a)
        for (int b = 0; b < 12; ++b)
          if (at[a / 6] >= 0 && at[b / 6] >= 0) K(at[a / 6] + a % 6, at[b / 6] + b % 6) += S(a, b);
    }
  }
  return K;
}

}  // namespace

MatX dense_mass_matrix(const Model& model, const VecX& q) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  const int N = model.dof();
  MatX M = MatX::Zero(N, N);
  for (const Body& b : bodies(model, q, false))
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) M(i, j) += (b.dW[i] * b.H * b.dW[j].transpose()).trace();
  for (int j = 0; j < model.m(); ++j) M(model.joint_index(j), model.joint_index(j)) += model.joints[j].drive.inertia;
  return M;
}

MatX dense_stiffness(const Model& model, const VecX& q, bool gravity) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  const int N = model.dof();
  MatX K = sde_sum(model, q, 1.0, 0.0);
  if (gravity)
    for (const Body& b : bodies(model, q, true))
      for (int i = 0; i < N; ++i)
        for (int j = 0; j < N; ++j) K(i, j) += model.gravity * (b.ddW[i][j] * b.H.col(3))[2];
  return K;
}

MatX dense_damping(const Model& model, const VecX& q, const VecX& v) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  MatX C = sde_sum(model, q, 0.0, 1.0);
  for (int j = 0; j < model.m(); ++j)
    C(model.joint_index(j), model.joint_index(j)) += model.joints[j].drive.damping_derivative(v[model.joint_index(j)]);
  return C;
}

}  // namespace rfem
