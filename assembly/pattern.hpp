#pragma once
// The bordered block pattern of the Newton matrix in CHOLMOD's compressed-column storage, upper
// triangle: rfe blocks first (6 columns each, block-tridiagonal because sde e joins rfes e−1 and
// e), the nb unknown base coordinates last (dense border and base block). Every column holds the
// contiguous rows first_row(c) … c, so the factor has no fill and slot(r, c) is arithmetic.
#include <vector>

namespace rfem {

class BorderedPattern {
 public:
  BorderedPattern(int n_rfes, int n_base);
  int n_rfes() const { return n_; }
  int n_base() const { return nb_; }
  int size() const { return 6 * n_ + nb_; }
  long nnz() const { return colptr_.back(); }
  int first_row(int c) const { return c < 6 * n_ ? 6 * std::max(0, c / 6 - 1) : 0; }
  /// Index into the value array of entry (r, c), r ≤ c.
  long slot(int r, int c) const { return colptr_[c] + (r - first_row(c)); }
  const std::vector<long>& colptr() const { return colptr_; }
  const std::vector<long>& rowind() const { return rowind_; }

 private:
  int n_, nb_;
  std::vector<long> colptr_, rowind_;
};

}  // namespace rfem
