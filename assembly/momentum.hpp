#pragma once
// Linear and angular momentum and the centre of mass of the whole manipulator (base links, rfes,
// payloads) in {0}.
// Without gravity and with no joint fixed to the ground (a free-floating base), both are
// conserved: the check that vibration and base motion exchange momentum correctly. Rotors of
// joint drives are not bodies of the model: their reflected inertia is left out.
#include "workspace.hpp"
#include "../core/model.hpp"

namespace rfem {

struct Momentum {
  Vec3 linear = Vec3::Zero();   ///< p = ∫ ẋ dm [kg m/s]
  Vec3 angular = Vec3::Zero();  ///< L = ∫ x × ẋ dm about the origin of {0} [kg m²/s]
  double mass = 0.0;            ///< of every body [kg]
  Vec3 centre = Vec3::Zero();   ///< centre of mass in {0} [m] (fixed when p = 0 stays so)
};

Momentum momentum(const Model& model, const VecX& q, const VecX& v, Workspace* ws = nullptr);

}  // namespace rfem
