#pragma once
// A flexible link made of segments, and its discretisation into rfes and sdes by the primary and
// secondary division (docs/formulation.md §2): each segment is cut into equal parts, one sde sits at the
// middle of each part, rfes lie between consecutive sdes. The link axis is x of the frame {r}.
#include <string>
#include <vector>

#include "section.hpp"

namespace rfem {

struct Segment {
  double length = 0.0;  ///< [m]
  Material material;
  Section section;
  int parts = 1;        ///< equal parts (= sdes) in this segment
};

/// A rigid body fixed to the link: a point mass or a body with inertia, e.g. an end
/// effector at the tip. It moves with the rfe whose span contains `at` (the last rfe for the tip),
/// whose mass, mass centre and inertia it joins.
struct Payload {
  double at = 0.0;          ///< position along the link axis of its reference point [m], 0 < at ≤ L
  Mat4 H = Mat4::Zero();    ///< pseudo-inertia about the reference point (at, 0, 0), {r} axes
};

struct FlexibleLink {
  std::vector<Segment> segments;
  std::vector<Payload> payloads;
  double damping_beta = 0.0;  ///< stiffness-proportional sde damping d = β c [s]
  double total_length() const;
  /// Throws std::invalid_argument unless the link has segments of positive length with at least
  /// one part each, valid materials and sections, β ≥ 0, and payloads of positive mass on it.
  void check() const;
};

/// Rigid finite element: mass, mass centre and pseudo-inertia [3.7] in its own frame, whose axes
/// are parallel to {r} (H carries products of inertia when pieces of two segments are combined).
struct Rfe {
  double mass = 0.0;
  Vec3 centre = Vec3::Zero();   ///< undeformed mass centre in {r}; C_k = Trans(centre)
  Mat4 H = Mat4::Zero();        ///< ∫[x;1][x;1]ᵀ dm about the mass centre
  double start = 0.0, end = 0.0;  ///< span along the link axis [m]
};

/// Spring-damping element between rfe `left` (−1 is rfe_0, rigid with {r}) and rfe `right`.
struct Sde {
  int left = -1, right = 0;
  Vec3 eta_left = Vec3::Zero(), eta_right = Vec3::Zero();  ///< attachment points [3.14]
  Vec3 c = Vec3::Zero();  ///< translational stiffness: axial EA/Δl, shear κGA/Δl (y, z) [N/m]
  Vec3 k = Vec3::Zero();  ///< rotational stiffness: torsion GJ/Δl, bending EIy/Δl, EIz/Δl [N m/rad]
  double position = 0.0;  ///< along the link axis [m]
  int segment = 0;
};

struct Discretisation {
  std::vector<Rfe> rfes;  ///< rfe_1 … rfe_n
  std::vector<Sde> sdes;  ///< sde_1 … sde_n; sde e joins rfe e−1 and rfe e
  Rfe rfe0;               ///< the clamped half-part, rigid with {r}
  Vec3 tip_eta = Vec3::Zero();  ///< free end on the elastic axis, in rfe_n's frame
  double length = 0.0;
  double damping_beta = 0.0;
  std::vector<Payload> payloads;  ///< (their inertia is in the rfes; kept for their positions)
  /// Modal reduction (solvers/reduction.hpp): keep the link's first `modes` clamped modes instead
  /// of its 6n rfe coordinates; 0 keeps every coordinate.
  int modes = 0;
  /// Static modal derivatives (solvers/modes.hpp, link_modes) of the first `derivatives` kept modes
  /// added to the basis as quasi-static coordinates; 0: none.
  int derivatives = 0;
  int n() const { return static_cast<int>(rfes.size()); }
  /// Its rigid counterpart (n = 0): no rfes, rfe_0 the whole link's inertia about {r}'s origin.
  Discretisation rigid() const;
};

/// The rfe whose span holds the point `s` of the link's axis (spans [start, end), the last one
/// [start, L]), or −1 for rfe_0's span (rigid with {r}).
int rfe_at(const Discretisation& d, double s);

/// Discretises the link with each segment's `parts`.
Discretisation discretise(const FlexibleLink& link);
/// Distributes n parts over the segments in proportion to their lengths (at least one each).
/// Throws std::invalid_argument if n is smaller than the number of segments.
std::vector<int> distribute_parts(const FlexibleLink& link, int n);

/// Pseudo-inertia ∫[x;1][x;1]ᵀ dm of a body from its mass, mass centre c and inertia tensor I_c
/// about c (all in the body frame).
Mat4 pseudo_inertia(double mass, const Vec3& c, const Mat3& I_c);

}  // namespace rfem
