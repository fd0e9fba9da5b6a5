#pragma once
// The immutable description of a manipulator built once from a case: the base chain with its rigid
// inertias, the mounting transform of the flexible link, and the link's rfes and sdes.
// Coordinates are numbered flexible first, base last: q = [q_1 … q_n (6 each); q_b (m)], the order
// in which the Newton matrix factorises without fill (FORMULATION.md §4).
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

  int m() const { return static_cast<int>(joints.size()); }
  int n() const { return link.n(); }
  int dof() const { return 6 * n() + m(); }
  int base_index(int j) const { return 6 * n() + j; }
};

/// Assembles a model; adds rfe_0's inertia to the last base link (FORMULATION.md §2).
Model make_model(std::vector<Joint> joints, const Mat4& mount, Discretisation link, double gravity);

/// The rigid manipulator of a model (n = 0): every rfe's inertia added to the carrying link, as if
/// the flexible link were infinitely stiff. Needs at least one joint.
Model rigidify(const Model& model);

}  // namespace rfem
