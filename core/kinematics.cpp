#include "kinematics.hpp"

#include "check.hpp"

namespace rfem {

namespace {

// v, a: the joint rates and accelerations by coordinate, or null for zero ones.
void base_kinematics_of(const Model& model, const VecX& q, const double* v, const double* a, BaseKinematics& out) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  const int N = static_cast<int>(model.nodes.size());
  for (auto* x : {&out.W, &out.Xi, &out.Wd, &out.Wdd, &out.Omega, &out.Alpha}) x->resize(N);
  for (int i = 0; i < N; ++i) {
    const Node& nd = model.nodes[i];
    const int p = nd.parent;
    const double qi = q[nd.coord], vi = v ? v[nd.coord] : 0.0, ai = a ? a[nd.coord] : 0.0;
    const Mat4 A = nd.has_pre ? Mat4(nd.pre * joint_transform(nd.motion, qi)) : joint_transform(nd.motion, qi);
    const Mat4 W = p >= 0 ? Mat4(out.W[p] * A) : Mat4(Mat4::Identity() * A);
    const Mat4 Omega = p >= 0 ? out.Omega[p] : Mat4::Zero();  // Σ over the ancestors
    const Mat4 Alpha = p >= 0 ? out.Alpha[p] : Mat4::Zero();
    out.W[i] = W;
    out.Xi[i] = W * joint_generator(nd.motion) * W.inverse();
    // Adding node i to its ancestors' sums: new quadratic terms 2 Ξ_j Ξ_i q̇_j q̇_i and Ξ_i² q̇_i².
    out.Alpha[i] = Alpha + (out.Xi[i] * ai + (2.0 * Omega + out.Xi[i] * vi) * out.Xi[i] * vi);
    out.Omega[i] = Omega + out.Xi[i] * vi;
    out.Wd[i] = out.Omega[i] * W;
    out.Wdd[i] = out.Alpha[i] * W;
  }
  out.frame.resize(model.links.size());
  for (size_t l = 0; l < model.links.size(); ++l) {
    const MountedLink& L = model.links[l];
    LinkFrame& f = out.frame[l];
    const int p = L.parent;
    const Mat4 Wp = p >= 0 ? out.W[p] : Mat4::Identity();
    f.Omega = p >= 0 ? out.Omega[p] : Mat4::Zero();
    f.Omega_dd = p >= 0 ? out.Alpha[p] : Mat4::Zero();
    f.B0 = Wp * L.mount;
    f.B0d = f.Omega * f.B0;
    f.B0dd = f.Omega_dd * f.B0;
    const Mat4& Om = f.Omega;
    const Mat4& Al = f.Omega_dd;
    f.w = Vec3(Om(2, 1), Om(0, 2), Om(1, 0));
    f.wd = 0.5 * Vec3(Al(2, 1) - Al(1, 2), Al(0, 2) - Al(2, 0), Al(1, 0) - Al(0, 1));
  }
}

}  // namespace

void base_kinematics(const Model& model, const VecX& q, const VecX& v, const VecX& a, BaseKinematics& out) {
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  RFEM_CHECK_ARGUMENT_SIZE(a.size(), model.dof(), "a");
  base_kinematics_of(model, q, v.data(), a.data(), out);
}

void base_kinematics(const Model& model, const VecX& q, const VecX& v, BaseKinematics& out) {
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  base_kinematics_of(model, q, v.data(), nullptr, out);
}

void base_kinematics(const Model& model, const VecX& q, BaseKinematics& out) {
  base_kinematics_of(model, q, nullptr, nullptr, out);
}

}  // namespace rfem
