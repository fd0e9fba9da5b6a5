#pragma once
// The integrator's vector work on the residual's team: each thread takes one contiguous part of the
// unknowns, the same part every call — about the rfes it evaluates in the residual (static schedule
// over chunks of 64 rfes) and eliminates in the chain solver (top and bottom sweeps). Done serially,
// that work left the other core waiting, then re-reading from the first core's cache every line of
// q, v, a it needed (docs/performance.md, "Two threads"). Elementwise work only: the same bits for
// any team.
#include <omp.h>

namespace rfem {

/// The first index of part t of [0, n) cut into T parts (at multiples of 8: a cache line of doubles).
inline long team_part(long n, int t, int T) { return t >= T ? n : (n * t / T) / 8 * 8; }

/// f(begin, end) for the parts of [0, n) on `team` threads (on the caller's alone if team ≤ 1), part
/// t starting at cut(t, T). f runs inside an OpenMP region: it must not throw.
template <class Cut, class F>
void for_parts(long n, int team, Cut&& cut, F&& f) {
  if (team <= 1) {
    f(0L, n);
    return;
  }
#pragma omp parallel num_threads(team)
  {
    const int t = omp_get_thread_num(), T = omp_get_num_threads();
    f(cut(t, T), cut(t + 1, T));
  }
}

/// The parts of [0, n) doubles, cut at cache lines (team_part).
template <class F>
void for_team_parts(long n, int team, F&& f) {
  for_parts(n, team, [n](int t, int T) { return team_part(n, t, T); }, f);
}

/// The parts of [0, n) items cut evenly (no cache-line rounding: for a few blocks of work, each
/// many lines long).
template <class F>
void for_team_items(long n, int team, F&& f) {
  for_parts(n, team, [n](int t, int T) { return t >= T ? n : n * t / T; }, f);
}

/// f(t, T) on each thread t of a team of T (T = 1 on the caller's alone if team ≤ 1): several loops'
/// parts (team_part) in one OpenMP region, where one region each cost a fork and a join. f must not
/// throw.
template <class F>
void for_team_threads(int team, F&& f) {
  if (team <= 1) {
    f(0, 1);
    return;
  }
#pragma omp parallel num_threads(team)
  f(omp_get_thread_num(), omp_get_num_threads());
}

}  // namespace rfem
