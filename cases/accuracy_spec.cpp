#include "accuracy_spec.hpp"

#include <fmt/core.h>

#include <cmath>
#include <cstdlib>

#include "case_file.hpp"

namespace rfem {

namespace {
double parse_number(const std::string& s, const std::string& where) {
  char* end = nullptr;
  const double v = s.empty() ? NAN : std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size())
    throw CaseError(where + ": '" + s + "' is not a number (a relative target, e.g. 1e-3, or QUANTITY=ERROR, e.g. peak:u1=2e-4)");
  return v;
}
}  // namespace

void check_relative_target(double relative, const std::string& where) {
  if (!(relative > 0.0 && relative < 1.0))
    throw CaseError(fmt::format("{}: a relative error between 0 and 1, e.g. 1e-3 (got {})", where, relative));
  if (relative < kMinRelativeTarget)
    throw CaseError(fmt::format("{}: {:g} is below what rfem can certify ({:g}: the integration tolerances it would need, "
                                "rtol = target/1000, reach round-off)",
                                where, relative, kMinRelativeTarget));
}

void add_accuracy(AccuracySpec& spec, const std::string& text, const std::string& where) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) {
    if (spec.relative > 0.0) throw CaseError(where + ": a relative target is given twice (" + fmt::format("{:g}", spec.relative) + ", " + text + ")");
    const double v = parse_number(text, where);
    check_relative_target(v, where);
    spec.relative = v;
    return;
  }
  const std::string q = text.substr(0, eq);
  const double v = parse_number(text.substr(eq + 1), where + " " + q);
  if (q.empty()) throw CaseError(where + ": '" + text + "' names no quantity (QUANTITY=ERROR, e.g. peak:u1=2e-4)");
  if (!(v > 0.0) || !std::isfinite(v))
    throw CaseError(fmt::format("{} {}: an absolute error bar must be positive and finite (got {})", where, q, v));
  for (const AbsoluteTarget& a : spec.absolute)
    if (a.quantity == q) throw CaseError(where + ": " + q + " is given a target twice");
  spec.absolute.push_back({q, v, where});
}

}  // namespace rfem
