#pragma once
// A target accuracy instead of an n (docs/accuracy.md): the case's [accuracy] table, the program's
// `--accuracy` (repeatable) and Python's accuracy=. rfem then chooses the integration tolerances
// and the number of rfes (studies/accuracy.hpp) and reports every value with its error bar.
#include <string>
#include <vector>

namespace rfem {

/// The tightest relative target rfem certifies: below it the integrator's tolerances (rtol =
/// target/1000 would pass 1e-11) and round-off in the values put the time error near the target.
inline constexpr double kMinRelativeTarget = 1e-8;
/// The accuracy a run without a target aims at: 1e-4 of each series' scale (docs/accuracy.md, "The
/// default tolerances, measured").
inline constexpr double kDefaultsAim = 1e-4;

struct AbsoluteTarget {
  std::string quantity;  ///< a quantity (studies/quantities.hpp), e.g. "peak:u1"
  double error = 0.0;    ///< its error bar must be at most this [the quantity's unit]
  std::string where;     ///< "file:line: accuracy.absolute" or "--accuracy" (messages)
};

struct AccuracySpec {
  /// Every reported value's error bar at most relative·its scale (0: none): a value's own
  /// magnitude, or its group's (a tip's displacements share one; docs/accuracy.md).
  double relative = 0.0;
  std::vector<AbsoluteTarget> absolute;  ///< named quantities with an absolute bar
  int max_n = 0;                         ///< the largest n the ladder may reach (0: kMaxTargetN)
  /// Wall time the ladder may take [s] (0: no limit): it stops before an n whose predicted end
  /// (the elapsed time plus that n's cost, extrapolated from the levels done) would pass it.
  double max_time = 0.0;
  bool given() const { return relative > 0.0 || !absolute.empty(); }
};

/// Adds one target to `spec`: "1e-3" (relative) or "QUANTITY=ERROR" (absolute, e.g.
/// "peak:u1=2e-4"). CaseError naming `where` for a value that is not a number, not positive, not
/// below 1 (relative) or below kMinRelativeTarget; the quantity's name is checked by the study.
void add_accuracy(AccuracySpec& spec, const std::string& text, const std::string& where = "--accuracy");
/// The same checks for a relative target given as a number (Python, the case file).
void check_relative_target(double relative, const std::string& where);

}  // namespace rfem
