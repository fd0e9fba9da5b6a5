#include "rfem/core/positions.hpp"

#include "rfem/core/check.hpp"
#include "rfem/core/kinematics.hpp"
#include "rfem/core/rotation.hpp"

namespace rfem {

Vec6 tip_motion(const Model& model, int l, const VecX& q) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  const MountedLink& L = model.links[l];
  Vec6 out = Vec6::Zero();
  if (L.n() == 0) return out;
  const Vec6 qn = q.segment<6>(model.rfe_index(l, L.n() - 1));
  DeformationTransform d;
  deformation_transform(qn, d);
  const Vec3& eta = L.d.tip_eta;
  out.head<3>() = qn.head<3>() + d.D.topLeftCorner<3, 3>() * eta - eta;
  out.tail<3>() = qn.tail<3>();
  return out;
}

Vec3 tip_deflection(const Model& model, int l, const VecX& q) {
  const Vec6 t = tip_motion(model, l, q);
  return {t[1], t[2], t[3]};
}

Vec3 point_in_link_frame(const Model& model, int l, double s, const VecX& q) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  const MountedLink& L = model.links[l];
  const int k = rfe_at(L.d, s);
  if (k < 0) return Vec3(s, 0.0, 0.0);  // rigid with {r}
  const Vec6 qk = q.segment<6>(model.rfe_index(l, k));
  DeformationTransform d;
  deformation_transform(qk, d, false);
  const Vec3 eta = Vec3(s, 0.0, 0.0) - L.d.rfes[k].centre;  // in the rfe's frame
  return L.d.rfes[k].centre + qk.head<3>() + d.D.topLeftCorner<3, 3>() * eta;
}

Vec3 point_position(const Model& model, int l, double s, const VecX& q) {
  std::vector<Vec3> pos, deflection;
  axis_points(model, l, {s}, q, pos, deflection);  // (checks l and q)
  return pos[0];
}

void axis_points(const Model& model, int l, const std::vector<double>& s, const VecX& q, std::vector<Vec3>& pos,
                 std::vector<Vec3>& deflection, std::vector<Mat3>* rotation) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  BaseKinematics bk;
  const VecX z = VecX::Zero(model.dof());
  base_kinematics(model, q, z, z, bk);
  const Mat4& B0 = bk.frame[l].B0;
  pos.resize(s.size());
  deflection.resize(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    const Vec3 local = point_in_link_frame(model, l, s[i], q);
    pos[i] = B0.topLeftCorner<3, 3>() * local + B0.topRightCorner<3, 1>();
    deflection[i] = B0.topLeftCorner<3, 3>() * (local - Vec3(s[i], 0.0, 0.0));
  }
  if (!rotation) return;
  rotation->resize(s.size());
  const MountedLink& L = model.links[l];
  for (size_t i = 0; i < s.size(); ++i) {
    const int k = rfe_at(L.d, s[i]);
    if (k < 0) {
      (*rotation)[i] = B0.topLeftCorner<3, 3>();
      continue;
    }
    DeformationTransform d;
    deformation_transform(q.segment<6>(model.rfe_index(l, k)), d, false);
    (*rotation)[i] = B0.topLeftCorner<3, 3>() * d.D.topLeftCorner<3, 3>();
  }
}

std::vector<double> axis_stations(const Model& model, int l) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  const Discretisation& d = model.links[l].d;
  std::vector<double> s{0.0};
  for (const auto& r : d.rfes) s.push_back(r.centre[0]);
  s.push_back(d.length);
  return s;
}

Vec3 tip_position(const Model& model, int l, const VecX& q) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  return point_position(model, l, model.links[l].d.length, q);
}

std::vector<Vec3> joint_positions(const Model& model, const VecX& q) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  BaseKinematics bk;
  const VecX z = VecX::Zero(model.dof());
  base_kinematics(model, q, z, z, bk);
  std::vector<Vec3> out;
  for (int i : model.joint_node) out.push_back(bk.W[i].topRightCorner<3, 1>());
  return out;
}

}  // namespace rfem
