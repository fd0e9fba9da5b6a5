#pragma once
// A one-line progress report for long runs on a terminal: simulated time, percent, steps per
// second and time left, redrawn at most five times a second on stderr. Silent when stderr is not
// a terminal or when quiet.
#include <chrono>
#include <string>

namespace rfem::app {

class Progress {
 public:
  Progress(std::string label, double t_end, bool quiet);
  /// Reports simulated time t after `steps` integrator steps.
  void update(double t, long steps);
  /// Clears the line (before a summary is printed).
  void finish();

 private:
  std::string label_;
  double t_end_;
  bool active_;
  bool drawn_ = false;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace rfem::app
