#pragma once
// A target accuracy on what a command reports (docs/accuracy.md): `rfem run`, `modes`, `static`
// with `--accuracy` (or the case's [accuracy]) report each value with its error bar. The values a
// command reports become quantities (studies/quantities.hpp); a refinement towards the target
// (studies/refine.hpp) chooses the tolerances and n; the command then runs at that n and those
// tolerances — its values are the ladder's finest, to the bit — and prints them with their bars.
#include <string>
#include <vector>

#include "../cases/accuracy_spec.hpp"
#include "refine.hpp"

namespace rfem {

/// One reported value with its error bar (solvers/refinement.hpp: what the parts mean).
struct Estimate {
  std::string quantity;
  double value = NAN;
  double error = NAN, error_space = NAN, error_time = NAN;  ///< NaN: no bar
  /// A run of reduced links: the reduction's estimated error (studies/reduction_error.hpp), in
  /// `error` too; NaN: none.
  double error_reduction = NAN;
  double observed_order = NAN;
  bool asymptotic = false;
  bool zero = false;          ///< zero at every n (the case's symmetry keeps it so): no bar needed
  double allowed = INFINITY;  ///< the bar the target asked for (inf: no target on this value)
  bool met() const { return zero || error <= allowed; }
};

/// The values a command reports, as quantities: those of one `group` share a scale for a
/// relative target (a tip's three displacements; a run's u1 and u2 of one link).
struct Reported {
  std::vector<std::string> quantities;
  std::vector<int> groups;
  std::vector<double> zero_below;  ///< RefineRequest::zero_below
  void add(const std::string& q, int group, double zero = 0.0) {
    quantities.push_back(q);
    groups.push_back(group);
    zero_below.push_back(zero);
  }
};

/// A peak below this (of the link's length [m], or [rad]) is zero by the case's symmetry: round-off
/// of a motion of order 1 is 1e-16…1e-11 (a reduced link's projection), a tenth of the smallest
/// relative target (kMinRelativeTarget) is 1e-9.
inline constexpr double kZeroPeak = 1e-9;

/// `rfem run`: every flexible link's peak |u1|, |u2| (one scale) and |θ| in every run of the
/// procedure that moves flexible links (not the paper's rigid run). CaseError for a case that cannot
/// run, runs from a saved state (its n is the state's) or has no flexible link.
Reported reported_by_run(const Case& cs);
/// `rfem modes`: the first `count` frequencies (each its own scale).
Reported reported_by_modes(int count);
/// `rfem linearize`: the linear model's first `count` frequencies about rest (`linear:K`).
Reported reported_by_linearize(int count);
/// `rfem static`: every link's tip displacements (one scale) and rotations (another), those that are
/// not zero at n = kFirstTargetN (the rest are zero by symmetry and stay so).
Reported reported_by_static(const Case& cs, const JointRate& rate = {});

struct AccuracyResult {
  AccuracySpec target;                ///< what was asked
  int n = 0;                          ///< the n the values are at (the ladder's finest)
  double rtol = NAN, atol = NAN;      ///< the tolerances of its runs (NaN: no time integration)
  bool met = false;                   ///< every value met its target
  std::vector<std::string> shortfall; ///< per value that missed it: why and by how much
  std::vector<Estimate> estimates;    ///< the reported values, then any other named by an absolute target
  std::vector<std::string> calibration;  ///< how the tolerances were chosen (RefineResult::calibration)
  std::vector<std::string> warnings;  ///< the refinement's, "QUANTITY: …" (why a value has no bar)
  RefineResult refinement;            ///< the ladder itself
  /// The estimate of a quantity by its text (nullptr if none).
  const Estimate* find(const std::string& quantity) const;
};

/// A command's target: the texts given (add_accuracy: "1e-3", "peak:u1=2e-4"; they replace the
/// case's [accuracy]), else the case's [accuracy] unless an n is given (the caller's choice wins);
/// `max_n` > 0 and `max_time` > 0 [s] replace the target's. None (given() false) if neither. CaseError
/// for an n with given texts unless `n_starts_ladder` (a refinement's --n is where its ladder starts),
/// for a limit without a target, and for a max_time that is not positive and finite.
AccuracySpec target_of(const Case& cs, const std::vector<std::string>& given, int n, int max_n, double max_time = 0.0,
                       bool n_starts_ladder = false);
/// Sets a refinement's targets (relative, absolute — a quantity named only by an absolute target
/// is added —, max_n) from `target`; CaseError for a bad target or an unknown quantity.
void apply_target(const Case& cs, const AccuracySpec& target, RefineRequest& rq);
/// The refinement the target asks for: `base` gives threads, rate, progress, stop and warnings.
/// CaseError for a bad target or an unknown quantity named by an absolute one (before any run).
AccuracyResult meet_accuracy(const Case& cs, const AccuracySpec& target, const Reported& reported, RefineRequest base = {});
/// Adds the estimates to a results file (dataset `accuracy`: a row per value; attributes
/// quantities, relative, n, rtol, atol, met, shortfall).
void write_accuracy(const std::string& path, const AccuracyResult& a);
/// The case at the result's tolerances (what the command then runs).
Case at_chosen_tolerances(const Case& cs, const AccuracyResult& a);

}  // namespace rfem
