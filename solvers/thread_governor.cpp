#include "thread_governor.hpp"

#include <algorithm>

namespace rfem {

namespace {
constexpr size_t kSamples = 12;      // units of work compared per team
constexpr double kProbeFirst = 0.5, kProbeMax = 8.0;  // s of work on the chosen team between probes
constexpr double kMargin = 0.9;      // a challenger must be 10 % faster to take over
// A fixed team falls back to one thread only if that is 25 % faster, and comes back once it is not
// slower: timing noise on an idle machine never moves it.
constexpr double kFixedMargin = 0.8;
// A probe whose first two timed evaluations take more than twice the other team's mean has lost:
// under foreign load a team's evaluation can take 30× one thread's (a time slice per barrier), and
// 13 of them would cost more than the run saves.
constexpr double kHopeless = 2.0;
constexpr int kHopelessAfter = 2;

// The mean, not the median: when another process shares a core, a team's steps are now fast, now
// stalled for a time slice; throughput is what counts.
double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}
}  // namespace

ThreadGovernor::ThreadGovernor(int max_threads, bool fixed)
    : max_(std::max(1, max_threads)), current_(max_), best_(max_), adaptive_(max_ > 1), fixed_(fixed), probe_every_(kProbeFirst) {
  // Time one thread first, then the full team: a run that starts on a loaded machine learns it at
  // once (a fixed team too: its first 13 evaluations on one thread cost < 1 % of a run), and a team
  // far slower than one thread is given up after two timed evaluations (kHopeless).
  if (adaptive_) {
    current_ = 1;
    probing_ = kSamples + 1;
  }
}

void ThreadGovernor::record(double seconds) {
  const int slot = current_ > 1 ? 1 : 0;
  ++count_[slot];
  if (!adaptive_) return;
  const bool probe = probing_ > 0;
  // The first evaluation after a switch is not timed: caches and sleeping threads are cold.
  if (!probe || probing_ <= static_cast<int>(kSamples)) {
    auto& s = sample_[slot];
    s.push_back(seconds);
    if (s.size() > kSamples) s.erase(s.begin());
    if (probe) {
      probe_sum_ += seconds;
      ++probe_timed_;
    }
  }
  if (!probe) {
    since_probe_ += seconds;
    if (since_probe_ > probe_every_) {  // challenge the chosen team
      current_ = current_ > 1 ? 1 : max_;
      probing_ = kSamples + 1;
      probe_sum_ = 0.0;
      probe_timed_ = 0;
    }
    return;
  }
  const int other = slot ^ 1;
  const bool hopeless = sample_[other].size() >= kSamples && probe_timed_ >= kHopelessAfter &&
                        probe_sum_ / probe_timed_ > kHopeless * mean(sample_[other]);
  if (--probing_ > 0 && !hopeless) return;
  probing_ = 0;
  probe_sum_ = 0.0;
  probe_timed_ = 0;
  if (hopeless) {  // the team not being timed stays (or becomes) the choice
    const int before = best_;
    best_ = other ? max_ : 1;
    current_ = best_;
    since_probe_ = 0.0;
    probe_every_ = best_ == before ? std::min(kProbeMax, 2 * probe_every_) : kProbeFirst;
    return;
  }
  if (sample_[other].size() < kSamples) {  // first round: now time the other team
    current_ = other ? max_ : 1;
    probing_ = kSamples + 1;
    return;
  }
  const double mine = mean(sample_[slot]), theirs = mean(sample_[other]);
  const int before = best_;
  if (fixed_) {
    const double one = slot == 0 ? mine : theirs, team = slot == 1 ? mine : theirs;
    const bool team_wins = best_ > 1 ? !(one < kFixedMargin * team) : team <= one;
    best_ = team_wins ? max_ : 1;
  } else {
    const bool incumbent = (best_ > 1) == (slot == 1);
    const bool keep_mine = incumbent ? mine <= theirs / kMargin : mine < kMargin * theirs;
    best_ = keep_mine ? current_ : (other ? max_ : 1);
  }
  current_ = best_;
  since_probe_ = 0.0;
  probe_every_ = best_ == before ? std::min(kProbeMax, 2 * probe_every_) : kProbeFirst;
}

}  // namespace rfem
