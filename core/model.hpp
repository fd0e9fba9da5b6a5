#pragma once
// The immutable description of a manipulator built once from a case: the base chain with its rigid
// inertias, the mounting transform of the flexible link, and the link's rfes and sdes.
// Coordinates are numbered flexible first, base last: q = [q_1 … q_n (6 each); q_b (m)], the order
// in which the Newton matrix factorises without fill (FORMULATION.md §4). The model owns this
// layout: other code asks rfe_index / joint_index instead of computing offsets.
#include "core/base_chain.hpp"
#include "core/link.hpp"

namespace rfem {

struct Model {
  std::vector<Joint> joints;  ///< base links; rfe_0's inertia is already added to the last one
  Mat4 mount = Mat4::Identity();  ///< {r} in the frame of the last base link
  Discretisation link;        ///< n = 0 is the rigid manipulator
  double gravity = 0.0;       ///< g [m/s²], acting along −z of {0}
  /// Joints 0–5 are a free-floating base (free_base_joints): x, y, z, yaw, pitch, roll.
  bool free_base = false;

  static constexpr int rfe_dofs = 6;  ///< coordinates of one rfe: x1, x2, x3, φ1, φ2, φ3

  int m() const { return static_cast<int>(joints.size()); }
  int n() const { return link.n(); }
  int flexible_dofs() const { return rfe_dofs * n(); }
  int dof() const { return flexible_dofs() + m(); }
  /// First coordinate of rfe k (k = 0 … n−1 for rfe_1 … rfe_n).
  int rfe_index(int k) const { return rfe_dofs * k; }
  /// Coordinate of joint j (0-based).
  int joint_index(int j) const { return flexible_dofs() + j; }
  /// The joints' part of a full coordinate vector (rates, accelerations, forces alike).
  Eigen::VectorBlock<VecX> joint_coords(VecX& x) const { return x.segment(flexible_dofs(), m()); }
  Eigen::VectorBlock<const VecX> joint_coords(const VecX& x) const { return x.segment(flexible_dofs(), m()); }
};

/// Assembles a model; adds rfe_0's inertia to the last base link (FORMULATION.md §2).
Model make_model(std::vector<Joint> joints, const Mat4& mount, Discretisation link, double gravity);

/// The rigid manipulator of a model (n = 0): every rfe's inertia added to the carrying link, as if
/// the flexible link were infinitely stiff. Needs at least one joint.
Model rigidify(const Model& model);

}  // namespace rfem
