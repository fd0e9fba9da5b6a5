#include "positions.hpp"

#include "check.hpp"
#include "kinematics.hpp"
#include "rotation.hpp"

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
  base_kinematics(model, q, bk);
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

PointMotion point_motion(const Model& model, int l, double s, const VecX& q, const VecX& v, const VecX& a) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  RFEM_CHECK_ARGUMENT_SIZE(a.size(), model.dof(), "a");
  BaseKinematics bk;
  base_kinematics(model, q, v, a, bk);
  const LinkFrame& f = bk.frame[l];
  const MountedLink& L = model.links[l];
  // The point and its body in {r}: position, velocity and acceleration relative to {r}, the body's
  // rotation and its rate (all zero for a point rigid with {r}).
  Vec3 p = Vec3(s, 0.0, 0.0), pd = Vec3::Zero(), pdd = Vec3::Zero();
  Mat3 R = Mat3::Identity(), Rd = Mat3::Zero();
  if (const int k = rfe_at(L.d, s); k >= 0) {
    const int i = model.rfe_index(l, k);
    DeformationTransform d;
    deformation_transform(q.segment<6>(i), d, true);
    const Vec4 eta(s - L.d.rfes[k].centre[0], -L.d.rfes[k].centre[1], -L.d.rfes[k].centre[2], 1.0);
    const Mat34 Dd = d_dot(d, v.segment<6>(i)), Ddd = d_ddot(d, v.segment<6>(i), a.segment<6>(i));
    p = L.d.rfes[k].centre + d.D.topRows<3>() * eta;
    pd = Dd * eta;
    pdd = Ddd * eta;
    R = d.D.topLeftCorner<3, 3>();
    Rd = Dd.leftCols<3>();
  }
  const Mat3 B = f.B0.topLeftCorner<3, 3>(), Bd = f.B0d.topLeftCorner<3, 3>(), Bdd = f.B0dd.topLeftCorner<3, 3>();
  PointMotion m;
  m.frame = f.B0;
  m.position = B * p + f.B0.topRightCorner<3, 1>();
  m.velocity = Bd * p + f.B0d.topRightCorner<3, 1>() + B * pd;
  m.acceleration = Bdd * p + f.B0dd.topRightCorner<3, 1>() + 2.0 * Bd * pd + B * pdd;
  m.rotation = B * R;
  const Mat3 W = (Bd * R + B * Rd) * m.rotation.transpose();  // [ω×]
  m.angular_velocity = Vec3(W(2, 1) - W(1, 2), W(0, 2) - W(2, 0), W(1, 0) - W(0, 1)) / 2.0;
  return m;
}

Vec3 tip_position(const Model& model, int l, const VecX& q) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  return point_position(model, l, model.links[l].d.length, q);
}

std::vector<Vec3> joint_positions(const Model& model, const VecX& q) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  BaseKinematics bk;
  base_kinematics(model, q, bk);
  std::vector<Vec3> out;
  for (int i : model.joint_node) out.push_back(bk.W[i].topRightCorner<3, 1>());
  return out;
}

}  // namespace rfem
