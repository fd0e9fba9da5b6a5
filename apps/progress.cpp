#include "apps/progress.hpp"

#include <fmt/core.h>
#include <unistd.h>

#include <cstdio>

namespace rfem::app {

Progress::Progress(std::string label, double t_end, bool quiet)
    : label_(std::move(label)), t_end_(t_end), active_(!quiet && isatty(fileno(stderr))),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

void Progress::update(double t, long steps) {
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double wall = std::chrono::duration<double>(now - start_).count();
  const double frac = t_end_ > 0 ? t / t_end_ : 1.0;
  const double left = frac > 0 ? wall * (1.0 - frac) / frac : 0.0;
  fmt::print(stderr, "\r{:<10} t = {:.3f} / {:.3f} s ({:5.1f} %), {:.0f} steps/s, {:.1f} s left   ", label_, t,
             t_end_, 100.0 * frac, wall > 0 ? steps / wall : 0.0, left);
  std::fflush(stderr);
  drawn_ = true;
}

void Progress::finish() {
  if (drawn_) fmt::print(stderr, "\r{:80}\r", "");
  drawn_ = false;
}

}  // namespace rfem::app
