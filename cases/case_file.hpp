#pragma once
// Case files: human-edited TOML describing materials, sections, the flexible link's segments and
// discretisation, the base joints and their rigid links, gravity and loads. Every key is checked;
// a bad file raises CaseError with a one-line "file:line: key: what is wrong" message.
// The format is documented in README.md ("Case files").
#include <stdexcept>
#include <string>
#include <vector>

#include "core/model.hpp"
#include "solvers/statics.hpp"

namespace rfem {

class CaseError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Case {
  std::string path;
  std::string text;  ///< the file as read (stored with results)
  std::string name, description;
  bool has_link = false;
  FlexibleLink link;
  int n = 0;                       ///< link.n if given (0: each segment's parts)
  Mat4 mount = Mat4::Identity();
  std::vector<Joint> joints;
  VecX joint_values, joint_rates;  ///< initial/held values and steady rates
  double gravity = 0.0;
  TipLoads loads;
};

/// Reads and validates a case; `overrides` are "key.path=value" strings applied before checking
/// (array elements by index: "joints.0.value=0.5", "link.segments.1.parts=4").
Case read_case(const std::string& path, const std::vector<std::string>& overrides = {});

/// Builds the model with n rfes (n > 0: distributed over the segments by length; n == 0: the
/// case's own discretisation). Throws CaseError for an impossible discretisation.
Model build_model(const Case& c, int n = 0);

}  // namespace rfem
