#pragma once
// What a series of values over n (a refinement study) says: successive changes, the observed
// order from three successive values, p = ln(|Δ_{i−1}| / |Δ_i|) / ln(n_i / n_{i−1}), Richardson
// extrapolation of the last value, and whether the series can be trusted to say so. An order and
// a Richardson value are given only where the changes shrink monotonically, the observed orders
// agree, and the last change stands clear of the integration error (when that is known).
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

struct Refinement {
  std::vector<RefinementRow> rows;
  /// Least-squares slope of ln|Δ_i| against ln n_i over all changes: an order that does not
  /// depend on the last three points alone (NaN with fewer than two changes).
  double fitted_order = 0.0;
  double integration_error = 0.0;  ///< |value(n_last) − value at tighter tolerances| (NaN: not known)
  std::vector<std::string> warnings;
  /// The extrapolated value of the last row (NaN when the series cannot be trusted).
  double reference() const { return rows.empty() ? 0.0 : rows.back().richardson; }
  /// One field of every row, as a column (e.g. column(&RefinementRow::value)).
  std::vector<double> column(double RefinementRow::*field) const {
    std::vector<double> out;
    for (const auto& r : rows) out.push_back(r.*field);
    return out;
  }
};

/// `ns` strictly increasing, one value each; `integration_error` NaN if unknown.
Refinement assess_refinement(const std::vector<int>& ns, const std::vector<double>& values, double integration_error);

}  // namespace rfem
