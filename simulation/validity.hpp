#pragma once
// Whether a solution stays in the range the model is built on (docs/formulation.md §3): deformation
// small relative to {r}. The sde law takes rotation differences Δφ as if they were small rotation
// vectors and measures Δx in {r} axes; for an rfe turned by φ relative to {r} both err by terms of
// relative size φ²/2 (cos φ ≈ 1 − φ²/2, and the axial/shear split of Δx turns by φ). At 0.1 rad that
// is 0.5 %, at 0.3 rad 4.5 %: beyond kSmallRotation the results are approximate, and a warning says
// where and when the solution left the range first, and how far it went.
#include <cmath>
#include <string>
#include <vector>

#include "../core/model.hpp"

namespace rfem {

/// The largest rotation of an rfe relative to {r} the model is trusted with [rad].
inline constexpr double kSmallRotation = 0.1;

/// An rfe turned this far relative to {r} [rad] (φ²/2 = 123 % error) or a link's tip this far
/// from its undeformed place (in link lengths): not an approximate solution any more but a diverged
/// one (an unstable controller, a loop that feeds energy in): the run ends (diverged()).
inline constexpr double kDivergedRotation = 1.5707963267948966;
inline constexpr double kDivergedDeflection = 1.0;

class ValidityMonitor {
 public:
  explicit ValidityMonitor(const Model& model);
  /// Looks at a state (full coordinates) at time t (NaN for a static state).
  void check(const VecX& q, double t);
  /// Why the state at t (full coordinates) is a diverged one ("diverged at t = … s: link 'L': …"),
  /// or "" if it is not (kDivergedRotation, kDivergedDeflection; non-finite coordinates).
  std::string diverged(const VecX& q, double t) const;
  /// Looks at the joints of an output sample against their rated limits (Joint::limits).
  void check_joints(const VecX& q, const VecX& v, const VecX& tau, double t);
  /// One warning per link whose rfes turned beyond kSmallRotation ("" context: "the solution"),
  /// and per joint and limit its solution exceeded.
  std::vector<std::string> warnings(const std::string& context) const;
  /// What it has seen, as doubles (a run's checkpoint), and back; restore throws
  /// std::invalid_argument for a state of another model.
  std::vector<double> save() const;
  void restore(const std::vector<double>& x);

 private:
  struct Link {
    std::string name;
    double peak = 0.0, peak_t = 0.0, first_t = 0.0;
    int peak_rfe = -1;
    bool exceeded = false;
  };
  struct Excess {  // of one joint's limit: the largest, when, and when first
    double peak = 0.0, peak_t = 0.0, first_t = NAN;
  };
  const Model& model_;
  std::vector<Link> links_;
  std::vector<Excess> range_, speed_, effort_;  // per joint
};

}  // namespace rfem
