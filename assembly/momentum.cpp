#include "momentum.hpp"

#include "assemble.hpp"
#include "rfe_kernels.hpp"
#include "../core/check.hpp"

namespace rfem {

namespace {

// L = vee(A − Aᵀ) for A = ∫ x ẋᵀ dm: (x × ẋ)_x = y ż − z ẏ = A_yz − A_zy, …
Vec3 vee_antisymmetric(const Mat3& A) { return Vec3(A(1, 2) - A(2, 1), A(2, 0) - A(0, 2), A(0, 1) - A(1, 0)); }

}  // namespace

Momentum momentum(const Model& model, const VecX& q, const VecX& v, Workspace* wsp) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  ws.check(model);
  BaseKinematics& bk = ws.bk;
  base_kinematics(model, q, v, bk);
  Vec3 lin = Vec3::Zero();
  Mat3 A = Mat3::Zero();
  Vec4 s = Vec4::Zero();  // ∫[x; 1] dm
  for (size_t i = 0; i < model.nodes.size(); ++i) {
    const Mat4& H = model.nodes[i].H;
    lin += (bk.Wd[i] * H.col(3)).head<3>();
    A += (bk.W[i] * H * bk.Wd[i].transpose()).topLeftCorner<3, 3>();
    s += bk.W[i] * H.col(3);
  }
  const int nchunks = ws.chunks(model);
  std::vector<Eigen::Matrix<double, 3, 4>> part(nchunks, Eigen::Matrix<double, 3, 4>::Zero());  // [A | lin]
  std::vector<Vec4> first(nchunks, Vec4::Zero());
#pragma omp parallel for schedule(static) num_threads(ws.parallel.team(model.n()))
  for (int c = 0; c < nchunks; ++c) {
    const Workspace::Chunk ch = ws.chunk[c];
    const MountedLink& L = model.links[ch.link];
    RfePose pose;
    Vec3 l;
    Mat3 a;
    // Sums in locals, stored once: neighbouring chunks' slots share cache lines (false sharing).
    Eigen::Matrix<double, 3, 4> sum = Eigen::Matrix<double, 3, 4>::Zero();
    Vec4 s1 = Vec4::Zero();
    for (int k = ch.begin; k < ch.end; ++k) {
      if (L.carries(k)) continue;  // a node's body
      const int ik = model.rfe_index(ch.link, k);
      rfe_pose(L.d.rfes[k], bk.frame[ch.link], q.segment<6>(ik), v.segment<6>(ik), Vec6::Zero(), pose, false);
      rfe_momentum_moments(L.d.rfes[k], pose, bk.frame[ch.link], v.segment<6>(ik), l, a);
      sum.leftCols<3>() += a;
      sum.col(3) += l;
      s1 += pose.W * L.d.rfes[k].H.col(3);
    }
    part[c] = sum;
    first[c] = s1;
  }
  for (int c = 0; c < nchunks; ++c) {  // chunk order: the same bits for any thread count
    A += part[c].leftCols<3>();
    lin += part[c].col(3);
    s += first[c];
  }
  Momentum out{lin, vee_antisymmetric(A)};
  out.mass = s[3];
  out.centre = s[3] > 0 ? Vec3(s.head<3>() / s[3]) : Vec3::Zero();
  return out;
}

}  // namespace rfem
