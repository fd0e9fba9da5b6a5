#pragma once
// Static equilibrium of the flexible link with the joints held at given values (and, for a
// steadily rotating base, given joint rates): f_el(q) + f_g(q) + h(q, v_b) = Q_tip(q), solved by
// Newton iteration with the CHOLMOD factor of the stiffness (elastic with geometric term, gravity,
// centrifugal), with load stepping when a full step does not converge.
#include "core/model.hpp"

namespace rfem {

/// Loads at the free end of the flexible link, on the elastic axis, in {r} axes (dead loads in
/// the base frame).
struct TipLoads {
  Vec3 force = Vec3::Zero();   ///< [N]
  Vec3 moment = Vec3::Zero();  ///< [N m]
};

struct StaticOptions {
  int max_iterations = 50;
  double tolerance = 1e-10;       ///< on the residual, relative to the applied load scale
  double step_tolerance = 1e-13;  ///< on the Newton correction, relative to the coordinates
  int max_load_steps = 64;
};

struct StaticResult {
  VecX q;               ///< full coordinates (flexible first, base last)
  int iterations = 0;   ///< Newton iterations in all load steps
  int load_steps = 0;
  double residual = 0;  ///< final residual norm [N]
};

/// Throws std::runtime_error if equilibrium cannot be found.
StaticResult solve_static(const Model& model, const VecX& qb, const VecX& vb, const TipLoads& loads,
                          const StaticOptions& opts = {});

/// Generalised force of the tip loads on rfe_n's coordinates.
Vec6 tip_generalised_force(const Model& model, const Vec6& qn, const TipLoads& loads);

/// Tip displacement (3, in {r}) and small rotation (3) of the free end relative to undeformed.
Vec6 tip_motion(const Model& model, const VecX& q);
/// Position of the free end (on the elastic axis) in the inertial frame {0} (full coordinates q).
Vec3 tip_position(const Model& model, const VecX& q);

}  // namespace rfem
