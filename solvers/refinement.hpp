#pragma once
// What a series of values over n (a refinement study) says: successive changes, the observed
// order from three successive values, p = ln(|Δ_{i−1}| / |Δ_i|) / ln(n_i / n_{i−1}), Richardson
// extrapolation of the last value, and whether the series can be trusted to say so. An order and
// a Richardson value are given only where the last two changes (the three levels the GCI uses) have
// one sign and shrink, the order is plausible, and the last change stands clear of the integration
// error (when that is known); earlier levels may lie before the asymptotic range.
#include <limits>
#include <string>
#include <vector>

namespace rfem {

struct RefinementRow {
  int n = 0;
  double value = 0.0;
  double change = 0.0;      ///< value − previous value (NaN for the first)
  double order = 0.0;       ///< observed order (NaN where it cannot be told)
  double richardson = 0.0;  ///< extrapolated value (NaN where it cannot be trusted)
};

/// The order the RFEM's values converge at as n grows (docs/accuracy.md: the rfe idealisation's
/// error in deflections and frequencies falls as 1/n²), against which an observed order is judged.
inline constexpr double kTheoreticalOrder = 2.0;
inline constexpr double kNoBar = std::numeric_limits<double>::quiet_NaN();

struct Refinement {
  std::vector<RefinementRow> rows;
  /// Least-squares slope of ln|Δ_i| against ln n_i over all changes: an order that does not
  /// depend on the last three points alone (NaN with fewer than two changes).
  double fitted_order = 0.0;
  double integration_error = 0.0;  ///< |value(n_last) − value at tighter tolerances| (NaN: not known)
  std::vector<std::string> warnings;
  /// The error bar of the last value: an estimate of its distance from the value of the model's
  /// equations solved exactly (docs/accuracy.md says what it leaves out: the model's own form).
  /// The space part is Roache's grid convergence index over the last two n,
  /// Fs·|Δ|/(r^p − 1) with r = n_m/n_{m−1}, p = min(observed, theoretical): Fs = 1.25 where the
  /// observed order is within 0.25 of the theoretical 2 and the last two orders agree (within 0.5),
  /// else 3 (orders below 1 or above 4 give no bar). The time part is the integration check's (0 for static and modal values; NaN where it
  /// was not measured: then it is not in `error`). All NaN, and `asymptotic` false, where the series
  /// cannot be trusted (the warnings say why): no bar rather than a false one.
  double error = kNoBar, error_space = kNoBar, error_time = kNoBar;
  double safety_factor = kNoBar;  ///< the GCI's Fs (NaN without a bar)
  bool asymptotic = false;
  /// The last observed order (NaN where it cannot be told).
  double observed_order() const { return rows.empty() ? 0.0 : rows.back().order; }
  /// The extrapolated value of the last row (NaN when the series cannot be trusted).
  double reference() const { return rows.empty() ? 0.0 : rows.back().richardson; }
  /// One field of every row, as a column (e.g. column(&RefinementRow::value)).
  std::vector<double> column(double RefinementRow::*field) const {
    std::vector<double> out;
    for (const auto& r : rows) out.push_back(r.*field);
    return out;
  }
};

/// `ns` strictly increasing, one value each; `integration_error` NaN if unknown (a dynamic value
/// without the check), 0 for a value without time integration (statics, modes).
Refinement assess_refinement(const std::vector<int>& ns, const std::vector<double>& values, double integration_error);

}  // namespace rfem
