// Helpers shared by the commands.
#include <fmt/core.h>

#include "apps/commands.hpp"

namespace rfem::app {

void print_json(const nlohmann::json& j) { fmt::print("{}\n", j.dump(2)); }

Case read_checked_case(const Common& c) {
  Case cs = read_case(c.case_path, c.overrides);
  for (const auto& w : cs.warnings) fmt::print(stderr, "rfem: warning: {}\n", w);
  return cs;
}

void joint_state(const Case& cs, const ModesOptions& o, VecX& qb, VecX& vb) {
  qb = cs.joint_values;
  vb = cs.joint_rates;
  if (o.rate_given) {
    if (o.joint < 1 || o.joint > static_cast<int>(cs.joints.size()))
      throw CaseError(cs.path + ": --joint " + std::to_string(o.joint) + ": the case has " +
                      std::to_string(cs.joints.size()) + " joints");
    vb[o.joint - 1] = o.rate;
  }
}

}  // namespace rfem::app
