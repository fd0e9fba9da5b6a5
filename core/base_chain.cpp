#include "base_chain.hpp"

#include "rotation.hpp"

namespace rfem {

Mat4 joint_transform(const Joint& j, double q) {
  if (j.axis != Vec3::UnitZ()) {
    const Mat4 X = homogeneous(rot_x(j.alpha), Vec3(j.a, 0, 0)) * homogeneous(rot_z(j.theta), Vec3(0, 0, j.d));
    if (j.type == JointType::Revolute) return X * homogeneous(Eigen::AngleAxisd(q, j.axis).toRotationMatrix(), Vec3::Zero());
    return X * homogeneous(Mat3::Identity(), q * j.axis);
  }
  const double theta = j.theta + (j.type == JointType::Revolute ? q : 0.0);
  const double d = j.d + (j.type == JointType::Prismatic ? q : 0.0);
  const Mat4 X = homogeneous(rot_x(j.alpha), Vec3(j.a, 0, 0));
  // RotX(α) TransX(a) = [RotX(α), RotX(α)·(a,0,0)] and (a,0,0) is fixed by RotX.
  return X * homogeneous(rot_z(theta), Vec3(0, 0, d));
}

Mat4 joint_generator(const Joint& j) {
  Mat4 G = Mat4::Zero();
  const Vec3& u = j.axis;
  if (j.type == JointType::Revolute) {
    G.topLeftCorner<3, 3>() << 0, -u.z(), u.y(), u.z(), 0, -u.x(), -u.y(), u.x(), 0;  // [u×]
  } else {
    G.topRightCorner<3, 1>() = u;
  }
  return G;
}

std::vector<Joint> free_base_joints(const Mat4& H) {
  const char* names[free_base_dofs] = {"base_x", "base_y", "base_z", "base_yaw", "base_pitch", "base_roll"};
  const Vec3 axes[free_base_dofs] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(),
                                     Vec3::UnitZ(), Vec3::UnitY(), Vec3::UnitX()};
  std::vector<Joint> js(free_base_dofs);
  for (int i = 0; i < free_base_dofs; ++i) {
    js[i].name = names[i];
    js[i].type = i < 3 ? JointType::Prismatic : JointType::Revolute;
    js[i].axis = axes[i];
  }
  js.back().H = H;
  return js;
}

}  // namespace rfem
