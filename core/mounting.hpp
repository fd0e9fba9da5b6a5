#pragma once
// Where a joint or a flexible link is mounted: on the ground {0}, on the body of a joint, or on a
// flexible link at a point of its elastic axis — then it moves with the rfe whose span holds that
// point — always through a constant transform from the parent's frame there. The default
// mounting and the checks (targets exist, points lie on their links, no cycles) live here only:
// the model and the case reader both call resolve_mountings.
#include <stdexcept>
#include <string>
#include <vector>

#include "types.hpp"

namespace rfem {

struct Mounting {
  enum class Kind {
    Chain,   ///< the default (resolve_mountings): a joint on the previous joint, a link on the chain's last joint
    Ground,  ///< on {0}
    Joint,   ///< on the body of joint `index`
    Link,    ///< on flexible link `index`, at `at` along its axis
  };
  Kind kind = Kind::Chain;
  int index = -1;
  /// On a link: distance from its clamped end along its axis [m], 0 … L; negative: the free end.
  double at = -1.0;
  /// The constant transform from the parent's frame (on a link: the frame at `at` on the elastic
  /// axis, axes of {r}, turning with the rfe there). A joint's own DH transform follows it.
  Mat4 X = Mat4::Identity();
};

/// A mounting that cannot be: which joint (or link) it belongs to, and why.
class MountingError : public std::invalid_argument {
 public:
  MountingError(bool joint, int index, const std::string& what) : std::invalid_argument(what), joint(joint), index(index) {}
  bool joint;  ///< a joint's mounting (else a link's)
  int index;   ///< of that joint or link (0-based)
};

/// Resolves the defaults and checks every mounting, in place:
///  - Kind::Chain: a joint sits on the previous joint (the ground for the first); a link on the last
///    joint of the chain from the ground — the last joint whose mountings do not lead through a
///    link, so a wrist mounted on the link comes after it — or on the ground without joints;
///  - a mounting on a link gets `at` in 0 … L (negative: L, the free end);
///  - targets must exist, points lie on their links, and the mountings form a tree.
/// Throws MountingError; a cycle reads "the mountings form a cycle (a -> b -> a)" (names from
/// joint_names and link_names), reported for its first member in the order joints, links.
void resolve_mountings(std::vector<Mounting>& joints, std::vector<Mounting>& links,
                       const std::vector<std::string>& joint_names, const std::vector<std::string>& link_names,
                       const std::vector<double>& link_lengths);

}  // namespace rfem
