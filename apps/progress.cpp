#include "progress.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>

namespace rfem::app {

ProgressLine::ProgressLine(bool quiet)
    : active_(!quiet && isatty(fileno(stderr))), start_(std::chrono::steady_clock::now()), last_(start_) {}

void ProgressLine::show(const Progress& p) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  if (p.run != run_) {
    run_ = p.run;
    start_ = now;
  } else if (now - last_ < std::chrono::milliseconds(200)) {
    return;
  }
  last_ = now;
  const double wall = std::chrono::duration<double>(now - start_).count();
  const double frac = p.t_end > 0 ? p.t / p.t_end : 1.0;
  const double left = frac > 0 ? wall * (1.0 - frac) / frac : 0.0;
  fmt::print(stderr, "\r{:<10} t = {:.3f} / {:.3f} s ({:5.1f} %), {:.0f} steps/s, {:.1f} s left   ", p.run, p.t, p.t_end,
             100.0 * frac, wall > 0 ? p.steps / wall : 0.0, left);
  std::fflush(stderr);
  drawn_ = true;
}

void ProgressLine::clear() {
  if (drawn_) fmt::print(stderr, "\r{:80}\r", "");
  drawn_ = false;
}

}  // namespace rfem::app
