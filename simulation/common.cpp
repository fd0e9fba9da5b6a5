#include "common.hpp"

#include <cmath>

namespace rfem {

void joint_state(const Case& cs, const JointRate& r, VecX& qb, VecX& vb) {
  qb = cs.joint_values;
  vb = cs.joint_rates;
  if (r.given) {
    if (r.joint < 1 || r.joint > static_cast<int>(cs.joints.size()))
      throw CaseError(cs.path + ": --joint " + std::to_string(r.joint) + ": the case has " +
                      std::to_string(cs.joints.size()) + " joints");
    if (!std::isfinite(r.rate))
      throw CaseError(cs.path + ": --rate " + std::to_string(r.rate) + ": must be a finite rate [rad/s or m/s]");
    vb[r.joint - 1] = r.rate;
  }
}

std::shared_ptr<const Model> model_of(const Case& cs, int n) { return std::make_shared<const Model>(build_model(cs, n)); }

}  // namespace rfem
