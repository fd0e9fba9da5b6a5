#pragma once
// How a run ends, and how a caller stops one. A run's status is written to results files as text
// ("running", "completed", "interrupted (signal 2)", "failed: why"); RunStatus is that text's one
// home, with parse() for reading it back.
#include <algorithm>
#include <atomic>
#include <iosfwd>
#include <memory>
#include <string>

namespace rfem {

struct RunStatus {
  enum class Kind { Running, Completed, Interrupted, Failed };
  Kind kind = Kind::Running;
  int signal = 0;      ///< Interrupted: the signal that asked for the stop (0: the caller's stop())
  std::string reason;  ///< Failed: why

  static RunStatus completed() { return {Kind::Completed, 0, {}}; }
  static RunStatus interrupted(int signal) { return {Kind::Interrupted, signal, {}}; }
  static RunStatus failed(std::string why) { return {Kind::Failed, 0, std::move(why)}; }
  bool is_completed() const { return kind == Kind::Completed; }
  /// "running", "completed", "interrupted (signal N)" or "interrupted (stopped)", "failed: …".
  std::string to_string() const;
  /// The inverse of to_string(); text it does not know is a failure with that text as its reason.
  static RunStatus parse(const std::string& text);
};

std::ostream& operator<<(std::ostream& os, const RunStatus& s);

/// A stop request shared by its copies (the caller keeps one, the run polls another): polled at
/// every integrator step, so a run ends cleanly within one step with every output so far kept.
/// request() is a lock-free atomic store, safe from a signal handler (through flag()).
class StopToken {
 public:
  StopToken() : flag_(std::make_shared<std::atomic<int>>(0)) {}
  /// Asks every run holding this token to stop; `signal` > 0 names the signal that asked.
  void request(int signal = 0) const { flag_->store(signal > 0 ? signal : -1); }
  /// Clears a request (a new run after an interrupted one).
  void reset() const { flag_->store(0); }
  bool requested() const { return flag_->load(std::memory_order_relaxed) != 0; }
  /// The signal of the request (0: none, or a request without a signal).
  int signal() const { return std::max(0, flag_->load()); }
  /// The flag itself, for a signal handler (stores the signal number).
  std::atomic<int>* flag() const { return flag_.get(); }

 private:
  std::shared_ptr<std::atomic<int>> flag_;
};

}  // namespace rfem
