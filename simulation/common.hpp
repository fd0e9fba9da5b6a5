#pragma once
// What the engine and every study share: where warnings go (the library never prints), the joint
// state of a case with an optional steady rate, and the case's model as a shared object.
#include <functional>
#include <memory>
#include <string>

#include "../cases/case_file.hpp"

namespace rfem {

/// Receives a study's warnings and notes, one line each ("FILE:LINE: key: …"); none: they are
/// dropped (also returned where a result has room for them).
using Warnings = std::function<void(const std::string&)>;

/// A steady rate of one joint for statics and modes (`rfem static|modes|refine --rate W --joint J`).
struct JointRate {
  bool given = false;
  double rate = 0.0;  ///< [rad/s or m/s]
  int joint = 1;      ///< 1-based
};

/// Joint values and rates of the case, with the steady rate applied (CaseError for a joint that
/// does not exist).
void joint_state(const Case& cs, const JointRate& rate, VecX& qb, VecX& vb);

/// The case's model with n rfes in all (0: the case's own discretisation), shared.
std::shared_ptr<const Model> model_of(const Case& cs, int n = 0);

}  // namespace rfem
