#include "check.hpp"

#include <cmath>
#include <sstream>

namespace rfem {

namespace {
std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}
}  // namespace

void throw_argument_error(const char* function, const std::string& what) {
  throw std::invalid_argument(std::string(function) + ": " + what);
}

void require_finite(const std::string& what, double value) {
  if (!std::isfinite(value)) throw std::invalid_argument(what + " must be finite (got " + num(value) + ")");
}

void require_positive(const std::string& what, double value) {
  require_finite(what, value);
  if (!(value > 0.0)) throw std::invalid_argument(what + " must be positive (got " + num(value) + ")");
}

void require_non_negative(const std::string& what, double value) {
  require_finite(what, value);
  if (value < 0.0) throw std::invalid_argument(what + " must not be negative (got " + num(value) + ")");
}

}  // namespace rfem
