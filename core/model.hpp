#pragma once
// The immutable description of a manipulator built once from a case: joints and
// flexible links, each mounted on the ground, on a joint's body or on a point of a flexible link,
// forming a tree; the rigid inertias; every link's rfes and sdes.
//
// Kinematics runs over a tree of one-coordinate *nodes*: every joint, and the six coordinates of
// every rfe that carries something (a joint, a link): its D = Trans(x) RotY(φ2) RotZ(φ3) RotX(φ1)
// [2.4] is the product of six one-coordinate transforms, so a body beyond it moves like a body
// beyond six joints (core/kinematics.hpp). Each node's frame is W = W_parent · pre · A(q).
//
// Coordinates: q = [rfes that carry nothing, link by link; carrying rfes; joints], 6 per rfe, 1 per
// joint: the order in which the Newton matrix factorises without fill (the carrying rfes and the
// joints form the dense border of every link's chain of rfes, docs/formulation.md §4). The model owns
// this layout: other code asks rfe_index / joint_index instead of computing offsets.
#include <string>

#include "base_chain.hpp"
#include "link.hpp"
#include "mounting.hpp"

namespace rfem {

/// One coordinate of the kinematic tree: a joint, or one coordinate of an rfe that carries bodies
/// (an rfe axis: a prismatic motion along or a rotation about one axis, no DH offsets).
struct Node {
  int parent = -1;             ///< −1: {0}; a parent comes before its children
  Joint motion;                ///< A(q) = joint_transform(motion, q)
  Mat4 pre = Mat4::Identity(); ///< constant transform before A (used when has_pre)
  bool has_pre = false;        ///< false: W = W_parent · A (a serial DH chain, the arithmetic of old)
  Mat4 H = Mat4::Zero();       ///< pseudo-inertia of everything rigid with this node's frame
  int coord = 0;               ///< its coordinate in q
  int joint = -1;              ///< the joint it is, or −1 for an rfe axis
  int link = -1, rfe = -1;     ///< an rfe axis: its link and rfe (0-based)
  std::vector<int> path;       ///< the nodes from the root to this one (itself last)
};

/// A flexible link placed in the model.
struct MountedLink {
  std::string name;
  Discretisation d;  ///< n = 0: rigid (the rigid manipulator), its inertia in its parent's body
  Mounting on;
  // Derived by make_model:
  int parent = -1;                 ///< node carrying {r} (−1: {0})
  Mat4 mount = Mat4::Identity();   ///< {r} in that node's frame
  std::vector<int> ancestors;      ///< nodes whose coordinates move {r}, root first
  std::vector<int> coord;          ///< first coordinate of each rfe
  /// Per rfe: the first of its six axis nodes if it carries a joint or a link, else −1. A carrying
  /// rfe's inertia is its last axis node's body; its coordinates sit in the border.
  std::vector<int> carrier;
  std::vector<int> carrier_sdes;   ///< sdes with a carrying rfe at either end (assembled serially)
  int n() const { return d.n(); }
  bool carries(int k) const { return carrier[k] >= 0; }
};

struct Model {
  std::vector<Joint> joints;       ///< every joint (inputs are per joint); joint j is node joint_node[j]
  std::vector<MountedLink> links;  ///< flexible links (none for a rigid manipulator without a link)
  std::vector<Node> nodes;         ///< the kinematic tree
  std::vector<int> joint_node;
  double gravity = 0.0;            ///< g [m/s²], acting along −z of {0}
  /// Joints 0–5 are a free-floating base (free_base_joints): x, y, z, yaw, pitch, roll.
  bool free_base = false;
  int rfes = 0;                    ///< all links' rfes
  int carrying = 0;                ///< rfes that carry a joint or a link

  static constexpr int rfe_dofs = 6;  ///< coordinates of one rfe: x1, x2, x3, φ1, φ2, φ3

  int m() const { return static_cast<int>(joints.size()); }
  int n() const { return rfes; }
  int flexible_dofs() const { return rfe_dofs * rfes; }
  /// Coordinates of the rfes that carry nothing (the chains of the Newton matrix), which come first.
  int chain_dofs() const { return rfe_dofs * (rfes - carrying); }
  int dof() const { return flexible_dofs() + m(); }
  /// First coordinate of rfe k (0-based) of link l.
  int rfe_index(int l, int k) const { return links[l].coord[k]; }
  /// Coordinate of joint j (0-based).
  int joint_index(int j) const { return flexible_dofs() + j; }
  /// The joints' part of a full coordinate vector (rates, accelerations, forces alike).
  Eigen::VectorBlock<VecX> joint_coords(VecX& x) const { return x.segment(flexible_dofs(), m()); }
  Eigen::VectorBlock<const VecX> joint_coords(const VecX& x) const { return x.segment(flexible_dofs(), m()); }
  /// Whether any link's sdes are damped.
  bool sdes_damped() const {
    for (const MountedLink& L : links)
      if (L.d.damping_beta != 0.0) return true;
    return false;
  }
  /// Whether node a is node b or one of its ancestors (a ≤ b in the tree).
  bool ancestor(int a, int b) const {
    const auto& p = nodes[b].path;
    const auto d = nodes[a].path.size();
    return d <= p.size() && p[d - 1] == a;
  }
};

/// Why `name` cannot name a joint or a link ("" if it can): names become components of results
/// paths (links/NAME/tip) and prefixes of refinement quantities, so they are non-empty, not "." or
/// "..", and hold no "/" and no control characters (a NUL would cut them short).
std::string name_problem(const std::string& name);

/// Builds a model: places every joint and link on what it is mounted on (throws
/// std::invalid_argument for a bad index, a point off its link or a cycle), adds each link's rfe_0
/// to the body that carries it (docs/formulation.md §2), numbers the coordinates.
Model make_model(std::vector<Joint> joints, std::vector<MountedLink> links, double gravity, bool free_base = false);
/// A serial chain of joints with one flexible link on the last one ({r} = `mount` in its frame),
/// or no link if `link` is empty (no rfes and no length).
Model make_model(std::vector<Joint> joints, const Mat4& mount, Discretisation link, double gravity);

/// The rigid manipulator of a model: every link rigid (n = 0), its rfes' inertia added to the body
/// that carries it, as if the links were infinitely stiff; what a link carried sits on that body.
Model rigidify(const Model& model);

}  // namespace rfem
