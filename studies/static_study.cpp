#include "static_study.hpp"

#include <cmath>

#include "../simulation/validity.hpp"

namespace rfem {

StaticStudy static_study(const Case& cs, int n, const JointRate& rate) {
  StaticStudy s;
  s.model = model_of(cs, n);
  const Model& model = *s.model;
  if (model.n() == 0) throw CaseError(cs.path + ": link: static analysis needs a flexible link");
  VecX qb, vb;
  joint_state(cs, rate, qb, vb);
  s.solution = solve_static(model, qb, vb, cs.loads);
  s.energies = energies(model, s.solution.q, VecX::Zero(model.dof()));
  if (!s.solution.q.allFinite() || !std::isfinite(s.energies.elastic) || !std::isfinite(s.energies.gravity))
    throw std::runtime_error("the static equilibrium is not finite (elastic energy " + std::to_string(s.energies.elastic) +
                             " J, gravity energy " + std::to_string(s.energies.gravity) + " J): check the case's values");
  for (int l = 0; l < static_cast<int>(model.links.size()); ++l)
    s.tips.push_back({model.links[l].name, model.links[l].n(), tip_motion(model, l, s.solution.q)});
  ValidityMonitor validity(model);
  validity.check(s.solution.q, NAN);
  s.warnings = validity.warnings("static equilibrium");
  return s;
}

}  // namespace rfem
