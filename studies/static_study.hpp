#pragma once
// Static equilibrium of a case (`rfem static`): the joints held at their values (or turning
// steadily), gravity and the tip loads of [loads]; the tips of every link and the energies.
#include <memory>
#include <string>
#include <vector>

#include "../assembly/assemble.hpp"
#include "../simulation/common.hpp"
#include "../solvers/statics.hpp"

namespace rfem {

struct LinkTip {
  std::string name;
  int n = 0;
  Vec6 motion = Vec6::Zero();  ///< displacement [m] in its {r}, then rotation [rad] (tip_motion)
};

struct StaticStudy {
  std::shared_ptr<const Model> model;
  StaticResult solution;
  std::vector<LinkTip> tips;  ///< every link's
  Energies energies;          ///< at rest: elastic and gravity
  std::vector<std::string> warnings;  ///< an equilibrium beyond the small deformation the model assumes
};

/// Throws CaseError without a flexible link, std::runtime_error if no finite equilibrium is found.
StaticStudy static_study(const Case& cs, int n = 0, const JointRate& rate = {});

}  // namespace rfem
