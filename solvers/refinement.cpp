#include "refinement.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace rfem {

namespace {
std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", x);
  return b;
}
}  // namespace

Refinement assess_refinement(const std::vector<int>& ns, const std::vector<double>& values, double integration_error) {
  if (ns.size() != values.size()) throw std::invalid_argument("one value per n is required");
  Refinement r;
  r.integration_error = integration_error;
  const size_t m = ns.size();
  for (size_t i = 0; i < m; ++i) r.rows.push_back({ns[i], values[i], NAN, NAN, NAN});
  for (size_t i = 1; i < m; ++i) r.rows[i].change = values[i] - values[i - 1];
  bool monotone = true;  // the last two changes (the GCI's three levels) of one sign and shrinking
  for (size_t i = 2; i < m; ++i) {
    const double d0 = r.rows[i - 1].change, d1 = r.rows[i].change;
    const bool ok = d0 != 0.0 && d1 != 0.0 && (d0 > 0) == (d1 > 0) && std::abs(d1) < std::abs(d0);
    if (i == m - 1) monotone = ok;
    if (ok) r.rows[i].order = std::log(std::abs(d0 / d1)) / std::log(double(ns[i]) / ns[i - 1]);
  }
  // Least squares of ln|Δ| against ln n.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int k = 0;
  for (size_t i = 1; i < m; ++i)
    if (r.rows[i].change != 0.0) {
      const double x = std::log(double(ns[i])), y = std::log(std::abs(r.rows[i].change));
      sx += x, sy += y, sxx += x * x, sxy += x * y, ++k;
    }
  r.fitted_order = k >= 2 ? -(k * sxy - sx * sy) / (k * sxx - sx * sx) : NAN;
  if (m < 3) {
    r.warnings.push_back("three values are needed for an observed order");
    return r;
  }
  bool trust = true;
  if (!monotone) {
    std::string signs;
    for (size_t i = 1; i < m; ++i) signs += (i > 1 ? ", " : "") + num(r.rows[i].change);
    r.warnings.push_back("the changes do not shrink monotonically (" + signs + "): the values are not in the asymptotic range, or noise dominates");
    trust = false;
  }
  const double p1 = r.rows[m - 1].order, p0 = m >= 4 ? r.rows[m - 2].order : NAN;
  // Orders that disagree do not confirm the asymptotic range: the bar's safety factor is then 3
  // (ASME V&V 20), not 1.25.
  const bool confirmed = !(std::isfinite(p1) && std::isfinite(p0) && std::abs(p1 - p0) > 0.5);
  if (!confirmed) r.warnings.push_back("the observed orders disagree (" + num(p0) + ", " + num(p1) + "): the bar takes Fs = 3");
  if (std::isfinite(p1) && (p1 < 0.5 || p1 > 8.0)) {
    r.warnings.push_back("the observed order " + num(p1) + " is implausible");
    trust = false;
  }
  const double last = std::abs(r.rows[m - 1].change);
  if (std::isfinite(integration_error) && !(last > 10.0 * integration_error)) {
    // The last change is within the time error's reach, so its order cannot be read. If the series
    // without the last level has a bar, and the last change has the same sign and is smaller (the
    // error still shrinks monotonically), that bar holds at the last n too, carried.
    if (trust && m >= 4) {
      const Refinement before = assess_refinement(std::vector<int>(ns.begin(), ns.end() - 1),
                                                  std::vector<double>(values.begin(), values.end() - 1), integration_error);
      const double d0 = r.rows[m - 2].change, d1 = r.rows[m - 1].change;
      if (before.asymptotic && d1 != 0.0 && (d0 > 0) == (d1 > 0) && std::abs(d1) < std::abs(d0)) {
        r.warnings.push_back("the last change (" + num(last) + ") is not well above the integration error (" +
                             num(integration_error) + "): the bar is n = " + std::to_string(ns[m - 2]) +
                             "'s, carried (the changes still shrink with one sign)");
        r.safety_factor = before.safety_factor;
        r.error_space = before.error_space;
        r.error_time = integration_error;
        r.error = r.error_space + integration_error;
        r.asymptotic = true;
        return r;
      }
    }
    r.warnings.push_back("the last change (" + num(last) + ") is not well above the integration error (" +
                         num(integration_error) + "): tighten simulation.rtol");
    trust = false;
  }
  if (!trust) return r;  // no extrapolated values, no error bar from a series that cannot be trusted
  for (size_t i = 2; i < m; ++i) {
    const double p = r.rows[i].order;
    if (!std::isfinite(p)) continue;
    const double q = std::pow(double(ns[i]) / ns[i - 1], p);
    r.rows[i].richardson = values[i] + r.rows[i].change / (q - 1.0);
  }
  if (!std::isfinite(p1)) return r;
  if (p1 < 1.0 || p1 > 4.0) {
    r.warnings.push_back("the observed order " + num(p1) + " is far from the theoretical " + num(kTheoreticalOrder) +
                         ": no error bar (refine further, or from a larger first n)");
    return r;
  }
  // Roache's GCI over the last two n: the order no higher than the theoretical one (a bar never
  // shrinks for an order that looks better than the method has), Fs by how near the order is.
  r.safety_factor = confirmed && std::abs(p1 - kTheoreticalOrder) <= 0.25 ? 1.25 : 3.0;
  const double ratio = double(ns[m - 1]) / ns[m - 2];
  r.error_space = r.safety_factor * last / (std::pow(ratio, std::min(p1, kTheoreticalOrder)) - 1.0);
  r.error_time = integration_error;
  r.error = r.error_space + (std::isfinite(integration_error) ? integration_error : 0.0);
  r.asymptotic = true;
  return r;
}

}  // namespace rfem
