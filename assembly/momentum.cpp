#include "assembly/momentum.hpp"

#include "assembly/assemble.hpp"
#include "assembly/rfe_kernels.hpp"

namespace rfem {

namespace {

// L = vee(A − Aᵀ) for A = ∫ x ẋᵀ dm: (x × ẋ)_x = y ż − z ẏ = A_yz − A_zy, …
Vec3 vee_antisymmetric(const Mat3& A) { return Vec3(A(1, 2) - A(2, 1), A(2, 0) - A(0, 2), A(0, 1) - A(1, 0)); }

}  // namespace

Momentum momentum(const Model& model, const VecX& q, const VecX& v, Workspace* wsp) {
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  const int n = model.n(), m = model.m();
  const Discretisation& d = model.link;
  if (ws.zero.size() != model.dof()) ws.zero = VecX::Zero(model.dof());
  BaseKinematics& bk = ws.bk;
  base_kinematics(model, base_coords(model, q), base_coords(model, v), base_coords(model, ws.zero), bk);
  Vec3 lin = Vec3::Zero();
  Mat3 A = Mat3::Zero();
  for (int i = 0; i < m; ++i) {
    const Mat4& H = model.joints[i].H;
    lin += (bk.Wd[i] * H.col(3)).head<3>();
    A += (bk.W[i] * H * bk.Wd[i].transpose()).topLeftCorner<3, 3>();
  }
  const int nchunks = ws.chunks(n);
  std::vector<Eigen::Matrix<double, 3, 4>> part(nchunks, Eigen::Matrix<double, 3, 4>::Zero());  // [A | lin]
#pragma omp parallel for schedule(dynamic, 1) num_threads(ws.parallel.team(n))
  for (int c = 0; c < nchunks; ++c) {
    RfePose pose;
    Vec3 l;
    Mat3 a;
    for (int k = ws.chunk_begin(c); k < ws.chunk_end(c, n); ++k) {
      rfe_pose(d.rfes[k], bk, rfe_coords(model, q, k), rfe_coords(model, v, k), rfe_coords(model, ws.zero, k), pose, false);
      rfe_momentum_moments(d.rfes[k], pose, bk, rfe_coords(model, v, k), l, a);
      part[c].leftCols<3>() += a;
      part[c].col(3) += l;
    }
  }
  for (const auto& p : part) {  // chunk order: the same bits for any thread count
    A += p.leftCols<3>();
    lin += p.col(3);
  }
  return Momentum{lin, vee_antisymmetric(A)};
}

}  // namespace rfem
