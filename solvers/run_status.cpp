#include "rfem/solvers/run_status.hpp"

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
  if (text.rfind(sig, 0) == 0) return interrupted(std::atoi(text.c_str() + sig.size()));
  const std::string failed_prefix = "failed: ";
  if (text.rfind(failed_prefix, 0) == 0) return failed(text.substr(failed_prefix.size()));
  return failed(text);
}

std::ostream& operator<<(std::ostream& os, const RunStatus& s) { return os << s.to_string(); }

}  // namespace rfem
