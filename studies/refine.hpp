#pragma once
// A refinement study (`rfem refine`): quantities over an increasing series of n, with changes,
// observed orders, Richardson values where the series can be trusted (solvers/refinement.hpp),
// and — for dynamic quantities — the integration error of the finest run, from a rerun at
// tolerances 100 times tighter. Dynamic quantities share one run of the procedure per n; only the
// runs they name are run. With `modes`, a series over a reduced link's modes instead: at one n,
// every flexible link reduced to m modes (link.modes = m, README "Reduced links") for each m, and
// the full model, each row's change its distance from the full model's value.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "../solvers/refinement.hpp"
#include "quantities.hpp"
#include "runs.hpp"

namespace rfem {

/// Where a study with a target starts without a given n, and the largest n it may reach by default.
inline constexpr int kFirstTargetN = 8;
inline constexpr int kMaxTargetN = 2048;

/// Round-off of a group's scale: a quantity no larger at every n is zero (its case's symmetry).
inline constexpr double kZeroOfScale = 1e-12;

struct RefineRequest {
  std::vector<int> ns;                  ///< strictly increasing, at least two (one with `modes`)
  /// A series over modes instead of n (strictly increasing, each ≥ 1): rows m …, then 0 (the full model).
  std::vector<int> modes;
  std::vector<std::string> quantities;  ///< at least one (studies/quantities.hpp)
  bool integration_check = true;        ///< rerun the finest n at 100× tighter tolerances
  /// A target instead of a ladder (kMinRelativeTarget ≤ accuracy < 1): the relative error bar every
  /// quantity's value must meet; dynamic quantities are then integrated at tolerances chosen for it
  /// (tolerances_for_target, measured and tightened at the first n), not the case's (Refinement::error ≤ accuracy·scale, the scale |value| or the largest
  /// |value| of its group). The series doubles n from the last of `ns` (from kFirstTargetN without
  /// one) until every bar meets its target, or the next n would pass max_n.
  std::optional<double> accuracy;
  /// Absolute targets, one per quantity (NaN: none; empty: none at all): the bar at most this.
  std::vector<double> absolute;
  /// Quantities that share a scale for the relative target (one id per quantity; empty: each its own).
  std::vector<int> groups;
  /// Per quantity, a magnitude below which it is zero by the case's symmetry (empty or 0: only
  /// round-off of its group's scale, kZeroOfScale, is): a reduced link's round-off reaches 1e-11 of
  /// a deflection, and a rotation that is its own group has no other scale.
  std::vector<double> zero_below;
  int max_n = kMaxTargetN;
  /// Wall time a command with a target may take [s] (0: none): its ladder stops before an n whose
  /// predicted end would pass it (that n's cost from the last two levels' growth, at least linear,
  /// 4 times over for dynamic values — the level, the integration check, the command's run —, twice
  /// for static and modal ones).
  double max_time = 0.0;
  JointRate rate;                       ///< for static and modal quantities
  std::vector<std::string> free;        ///< joints that move with modal quantities' modes (`rfem modes --free`)
  int threads = 0;
  StopToken stop;                       ///< ends the study after the current run; rows done are kept
  /// Before each n (index from 0, count, n; index = count for the integration check; count 0 in a
  /// ladder towards a target, index −1 while the tolerances are chosen there); with `modes`, before
  /// each m (n the m; 0: the full model, first).
  std::function<void(int index, int count, int n)> on_n;
  std::function<void(const Progress&)> progress;  ///< inside each run
  std::vector<RunObserver*> observers;  ///< see every run ("n12/kinematic", "check_n24/run")
  Warnings warn;
};

struct RefineResult {
  std::vector<Quantity> quantities;
  std::vector<int> ns;                 ///< the n done (all, unless stopped)
  /// Per quantity. With `modes`: a row per m done (RefinementRow::n the m; change: value − the full
  /// model's; order, Richardson NaN) and the full model's row last (n = 0, change 0).
  std::vector<Refinement> tables;
  std::vector<int> modes;              ///< the m of the rows (0: the full model); empty for a series over n
  RunStatus status;                    ///< completed, or interrupted
  bool dynamic = false;                ///< some quantity needed runs
  /// With a target (RefineRequest::accuracy): whether every bar met it, and if not, per quantity
  /// that did not, why and by how much (one line each: not success).
  bool met = false;
  std::vector<std::string> shortfall;
  /// Why a ladder towards a target stopped short of it, if a limit did ("" otherwise): the next n,
  /// its predicted end and max_time, when the wall-time limit did.
  std::string time_limit;
  std::vector<double> allowed;         ///< with a target: each quantity's bar must be ≤ this (inf: no target)
  /// Per quantity: zero at every n, to kZeroOfScale of its group's scale or below its zero_below (by the case's symmetry): no bar needed.
  std::vector<bool> zero;
  double rtol = 0.0, atol = 0.0;       ///< the tolerances the runs used (dynamic quantities; chosen or the case's)
  /// With a relative target and dynamic quantities: how the tolerances were chosen, a line per try.
  std::vector<std::string> calibration;
};

/// The integration tolerances a relative target asks for (docs/accuracy.md, measured there): rtol =
/// min(1e-5, target/1000), atol = rtol/100 [m, rad] and atol_velocity no looser than rtol·1000 (the
/// defaults' ratios), the rest as in `o`.
IntegratorOptions tolerances_for_target(IntegratorOptions o, double relative);
/// Every tolerance `factor` times tighter (rtol, atol, atol_velocity, atol_energy) and as many more
/// steps allowed: the integration check's rerun (factor 100), a target's tightening (10).
IntegratorOptions tightened(IntegratorOptions o, double factor);

/// Checks every quantity and every n before the first run (CaseError), then runs the study.
/// A run that does not complete throws std::runtime_error ("n = 24: force failed: …").
RefineResult refine(const Case& cs, const RefineRequest& request);

/// Checks a request without running it (what refine() checks first); returns the parsed quantities.
std::vector<Quantity> check_refinement(const Case& cs, const RefineRequest& request);

}  // namespace rfem
