#include "assembly/pattern.hpp"

namespace rfem {

BorderedPattern::BorderedPattern(int n_rfes, int n_base) : n_(n_rfes), nb_(n_base) {
  const int N = size();
  colptr_.assign(N + 1, 0);
  for (int c = 0; c < N; ++c) colptr_[c + 1] = colptr_[c] + (c - first_row(c) + 1);
  rowind_.resize(colptr_.back());
  for (int c = 0; c < N; ++c)
    for (int r = first_row(c); r <= c; ++r) rowind_[slot(r, c)] = r;
}

}  // namespace rfem
