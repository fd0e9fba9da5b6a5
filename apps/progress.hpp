#pragma once
// A one-line progress report for long runs on a terminal: the run, simulated time, percent, steps
// per second and time left, redrawn at most five times a second on stderr. Silent when stderr is
// not a terminal or when quiet.
#include <chrono>
#include <string>

#include "../studies/runs.hpp"

namespace rfem::app {

class ProgressLine {
 public:
  explicit ProgressLine(bool quiet);
  /// Shows where a run is (a new run name starts its own clock).
  void show(const Progress& p);
  /// Clears the line (before a summary is printed).
  void clear();

 private:
  bool active_;
  bool drawn_ = false;
  std::string run_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace rfem::app
