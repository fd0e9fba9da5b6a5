#pragma once
// Chooses the team size of the kernels by timing them. Results are the same bits for any team
// size (assembly/workspace.hpp), so the choice may change at any time: the governor runs with the
// team it believes fastest and now and then tries the other for a few units of work (ESDIRK
// steps, normalised per residual evaluation; IDA: residual evaluations). A challenger must win by
// 10 % on the mean; each lost challenge doubles the time to the next (0.5 s → 8 s of work), so
// a clear choice costs little. On an idle machine the second core pays from a few hundred rfes
// on; below that, or when another process keeps a core busy, one thread wins and is kept — so two
// threads are never much slower than one.
//
// A team the user fixed (--threads N) is kept, with a safety net: now and then one thread is timed
// against it, and only if one thread is clearly faster (by 25 %: a core taken by another process,
// where the team waits for it at every barrier) does the run fall back to one thread until the
// team is no slower again. An idle machine never falls back; results are the same bits either way.
#include <chrono>
#include <vector>

namespace rfem {

class ThreadGovernor {
 public:
  /// `max_threads` ≤ 1: one thread. `fixed`: the user's team, one thread only while it is
  /// measured clearly faster (the safety net above).
  ThreadGovernor(int max_threads, bool fixed);
  /// Team size for the next evaluation.
  int threads() const { return current_; }
  /// Reports the wall time of an evaluation run with threads().
  void record(double seconds);
  /// Evaluations so far with one thread and with more.
  long evaluations(int team) const { return team > 1 ? count_[1] : count_[0]; }

 private:
  int max_, current_, best_;
  bool adaptive_, fixed_;
  std::vector<double> sample_[2];  // recent times of 1 and max threads
  long count_[2] = {0, 0};
  double since_probe_ = 0.0;       // wall time since the last probe [s]
  double probe_every_ = 0.5;       // [s], doubled after each lost challenge
  int probing_ = 0;                // evaluations left in the current probe
  double probe_sum_ = 0.0;         // the current probe's timed evaluations: their sum and count
  int probe_timed_ = 0;
};

}  // namespace rfem
