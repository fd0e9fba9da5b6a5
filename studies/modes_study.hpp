#pragma once
// Natural frequencies and mode shapes of a case (`rfem modes`): joints held or freed, about the
// static equilibrium or a steady rotation; for one uniform segment on a held, non-rotating base
// without gravity, the exact value each mode converges to beside it.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../results/writer.hpp"
#include "../simulation/common.hpp"
#include "../solvers/modes.hpp"

namespace rfem {

struct ModesRequest {
  int n = 0;          ///< rfes in all (0: the case's discretisation)
  int count = 6;      ///< modes wanted (capped at 6n + free joints)
  JointRate rate;     ///< a steady joint rate
  /// Joints that move with the modes: numbers from 1, names, or "base" (a free base's six).
  std::vector<std::string> free;
};

/// The value a mode converges to as n grows (docs/formulation.md §7).
struct ModeReference {
  double reference_hz = 0.0;   ///< Timoshenko cantilever (bending) or rod theory (axial, torsion)
  std::string theory;          ///< "Timoshenko" or "rod"
  double relative_error = 0.0; ///< (f − reference) / reference: the discretisation's, ∝ 1/n²
  std::optional<double> euler_bernoulli_hz;  ///< bending modes: the Euler–Bernoulli value
};

struct ModesStudy {
  std::shared_ptr<const Model> model;
  ModesResult modes;
  int requested = 0, count = 0;          ///< modes asked for and computed (count ≤ 6n + free)
  std::vector<int> free;                 ///< freed joints (0-based)
  std::vector<std::string> free_names;
  VecX rates;                            ///< the joints' steady rates
  std::vector<int> index_of_kind;        ///< per mode: 1 for the first of its kind, …
  bool has_reference = false;            ///< exact values apply
  std::vector<ModeReference> reference;  ///< per mode, when they apply
  std::vector<std::string> warnings;     ///< modes whose two Lanczos solutions disagree
  double frequency_hz(int i) const;
};

/// Throws CaseError for a case without a flexible link or a bad --free.
ModesStudy modes_study(const Case& cs, const ModesRequest& request);
/// ModesRequest::free resolved to 0-based joints of `model` (CaseError naming an unknown one).
std::vector<int> free_joints(const Case& cs, const Model& model, const std::vector<std::string>& names);

/// Writes the modes into a results file: group `modes` with `frequency` (Hz), `omega` (rad/s),
/// `shapes` (a row per mode over the rfe coordinates and the free joints, columns named
/// LINK.rfeK.x1 … phi3, M-normalised), `equilibrium` (every coordinate of the state they are about)
/// and each link's `links/NAME/rfe_centre`; attributes `kinds` and `free_joints`.
void write_modes(ResultsWriter& file, const ModesStudy& s);

}  // namespace rfem
