#include "core/model.hpp"

namespace rfem {

Model make_model(std::vector<Joint> joints, const Mat4& mount, Discretisation link, double gravity) {
  Model m;
  m.joints = std::move(joints);
  m.mount = mount;
  m.link = std::move(link);
  m.gravity = gravity;
  if (!m.joints.empty() && m.link.n() > 0) {
    // rfe_0 is rigid with {r}: its pseudo-inertia moves to the carrying link's frame (X H Xᵀ).
    const Mat4 X = m.mount * homogeneous(Mat3::Identity(), m.link.rfe0.centre);
    m.joints.back().H += X * m.link.rfe0.H * X.transpose();
  }
  return m;
}

Model rigidify(const Model& model) {
  std::vector<Joint> joints = model.joints;
  for (const Rfe& r : model.link.rfes) {
    const Mat4 X = model.mount * homogeneous(Mat3::Identity(), r.centre);
    joints.back().H += X * r.H * X.transpose();
  }
  Model r = make_model(std::move(joints), model.mount, Discretisation{}, model.gravity);
  r.free_base = model.free_base;
  return r;
}

}  // namespace rfem
