#include "run_status.hpp"

#include <cstdlib>
#include <ostream>

namespace rfem {

std::string RunStatus::to_string() const {
  switch (kind) {
    case Kind::Running: return "running";
    case Kind::Completed: return "completed";
    case Kind::Interrupted:
      return signal > 0 ? "interrupted (signal " + std::to_string(signal) + ")" : std::string("interrupted (stopped)");
    case Kind::Failed: return "failed: " + reason;
  }
  return "failed: " + reason;
}

RunStatus RunStatus::parse(const std::string& text) {
  if (text == "running") return {};
  if (text == "completed") return completed();
  if (text == "interrupted (stopped)") return interrupted(0);
  const std::string sig = "interrupted (signal ";
  if (text.rfind(sig, 0) == 0) {  // a signal number that is one (1 … 2³¹−1), then ")"
    const std::string digits = text.substr(sig.size(), text.size() - sig.size() - 1);
    if (text.back() == ')' && !digits.empty() && digits.size() <= 10 &&
        digits.find_first_not_of("0123456789") == std::string::npos) {
      const long long n = std::stoll(digits);
      if (n > 0 && n <= 2147483647LL) return interrupted(static_cast<int>(n));
    }
    return failed(text);
  }
  const std::string failed_prefix = "failed: ";
  if (text.rfind(failed_prefix, 0) == 0) return failed(text.substr(failed_prefix.size()));
  return failed(text);
}

std::ostream& operator<<(std::ostream& os, const RunStatus& s) { return os << s.to_string(); }

}  // namespace rfem
