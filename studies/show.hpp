#pragma once
// What a case builds (`rfem show`): the assembled tree — every joint, link, payload and body with
// what it is mounted on and where, its mass and length, its coordinates, each joint's input — to
// check a case against its drawing before running it.
#include <string>
#include <vector>

#include "../simulation/common.hpp"

namespace rfem {

struct TreeEntry {
  std::string kind;    ///< "joint", "link", "payload"
  std::string name;
  int depth = 0;       ///< in the tree (0: on the ground)
  std::string parent;  ///< what it is mounted on: "ground", a joint's or link's name
  std::string where;   ///< on a link: "tip" or "at 0.4 m" (empty otherwise)
  double mass = 0.0;   ///< joint: its body; link: its segments and payloads; payload: its own [kg]
  double length = 0.0; ///< link: [m]
  int rfes = 0;        ///< link
  std::string detail;  ///< joint: type, axis, input; link: segments; payload: where on the link
  std::string coordinates;  ///< which entries of q: "q[97]", "q[1…48]"
};

struct ModelSummary {
  std::string name;
  int n = 0, m = 0, dof = 0;
  int unknowns = 0;          ///< rfe coordinates (a reduced link's: axial + modes + at most d(d + 1)/2 derivatives) + joints under force input
  double mass = 0.0;         ///< of every body [kg]
  std::vector<TreeEntry> entries;  ///< depth first, children after their parent
  std::string urdf;                ///< the URDF file of the base ("" if none)
  std::vector<TreeEntry> frames;   ///< its links (kind "frame"): the body each is welded to, and where
};

/// The tree of the case's model with n rfes in all (0: the case's own discretisation).
ModelSummary show_model(const Case& cs, int n = 0);
/// The same as text, one line per entry, indented by depth.
std::string format_summary(const ModelSummary& s);

}  // namespace rfem
