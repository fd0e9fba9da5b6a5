#pragma once
// Where a joint or a flexible link is mounted (issue 10 §1): on the ground {0}, on the body of a
// joint, or on a flexible link at a point of its elastic axis — then it moves with the rfe whose
// span holds that point — always through a constant transform from the parent's frame there.
#include "core/types.hpp"

namespace rfem {

struct Mounting {
  enum class Kind {
    Chain,   ///< a joint on the previous joint (the ground for the first), a link on the last joint
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

}  // namespace rfem
