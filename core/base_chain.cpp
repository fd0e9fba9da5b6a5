#include "core/base_chain.hpp"

#include "core/rotation.hpp"

namespace rfem {

Mat4 joint_transform(const Joint& j, double q) {
  const double theta = j.theta + (j.type == JointType::Revolute ? q : 0.0);
  const double d = j.d + (j.type == JointType::Prismatic ? q : 0.0);
  const Mat4 X = homogeneous(rot_x(j.alpha), Vec3(j.a, 0, 0));
  // RotX(α) TransX(a) = [RotX(α), RotX(α)·(a,0,0)] and (a,0,0) is fixed by RotX.
  return X * homogeneous(rot_z(theta), Vec3(0, 0, d));
}

Mat4 joint_generator(const Joint& j) {
  Mat4 G = Mat4::Zero();
  if (j.type == JointType::Revolute) {
    G(1, 0) = 1.0;
    G(0, 1) = -1.0;
  } else {
    G(2, 3) = 1.0;
  }
  return G;
}

}  // namespace rfem
