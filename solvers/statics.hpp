#pragma once
// Static equilibrium of the flexible links with the joints held at given values (and, for a
// steadily rotating base, given joint rates): f_el(q) + f_g(q) + h(q, v_b) = Q_tip(q), solved by
// Newton iteration with the CHOLMOD factor of the stiffness (elastic with geometric term, gravity,
// centrifugal), with load stepping when a full step does not converge.
#include "../core/model.hpp"
#include "../core/positions.hpp"
#include "../assembly/workspace.hpp"

namespace rfem {

/// Loads at the free end of a flexible link, on the elastic axis, in its {r} axes (dead loads in
/// the frame the link is mounted in).
struct TipLoads {
  Vec3 force = Vec3::Zero();   ///< [N]
  Vec3 moment = Vec3::Zero();  ///< [N m]
  int link = -1;               ///< the link (−1: the last one)
};

class Reduction;

struct StaticOptions {
  int max_iterations = 50;
  double tolerance = 1e-10;       ///< on the residual, relative to the applied load scale
  double step_tolerance = 1e-13;  ///< on the Newton correction, relative to the coordinates
  int max_load_steps = 64;
  Parallelism parallel;  ///< the residual's team (a run's: its `threads`)
  /// The model's modal reduction at these joint values, if the caller has it (solvers/reduction.hpp);
  /// a model with reduced links gets one built otherwise. The equilibrium is then the reduced one.
  const Reduction* reduction = nullptr;
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

/// Generalised force of tip loads on the coordinates qn of link l's last rfe, the loads in {r} axes.
Vec6 tip_generalised_force(const Model& model, int l, const Vec6& qn, const TipLoads& loads);
/// Generalised forces (all coordinates) of dead tip loads on link loads.link: force and moment are
/// given in the axes of the link's {r} at the undeformed state (every rfe coordinate zero) and keep
/// that direction in {0}; Q_j = F·∂p/∂q_j + M·ω_j over every coordinate that moves the tip — the
/// link's last rfe and every node that carries the link (a link on another's tip loads both).
VecX tip_load_forces(const Model& model, const VecX& q, const TipLoads& loads);

/// The link tip loads act on (TipLoads::link, −1 for the last); throws std::invalid_argument if
/// there is none.
int loaded_link(const Model& model, const TipLoads& loads);

}  // namespace rfem
