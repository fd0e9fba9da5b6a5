#pragma once
// Storage of the bordered block matrix of the Newton system (FORMULATION.md §4), its upper
// triangle block by block: for each rfe k (stride 72 + 6 nb values)
//   D_k = S(k, k)     6×6, row-major (its upper triangle is the matrix; the lower is scratch),
//   E_k = S(k−1, k)   6×6, row-major (rows of rfe k−1; unused for k = 0: rfe_0 is rigid),
//   B_k = S(k, base)  6×nb, row-major,
// then the base block Z (nb×nb, row-major, upper triangle). Coordinates are numbered rfes first,
// base last, so the Cholesky factor has no fill beyond these blocks: the chain solver factorises
// in place, and CHOLMOD receives the same entries in compressed columns (built on first use).
#include <mutex>
#include <vector>

#include "core/types.hpp"

namespace rfem {

class BorderedPattern {
 public:
  BorderedPattern(int n_rfes, int n_base);
  int n_rfes() const { return n_; }
  int n_base() const { return nb_; }
  int size() const { return 6 * n_ + nb_; }
  /// Values to store (the storage size, not the count of distinct entries).
  long nnz() const { return stride_ * n_ + static_cast<long>(nb_) * nb_; }
  /// Distinct entries of the upper triangle (21 + 36 + 6 nb per rfe, less rfe 1's coupling).
  long entries() const;
  long stride() const { return stride_; }
  long diag(int k) const { return stride_ * k; }
  long coupling(int k) const { return stride_ * k + 36; }
  long border(int k) const { return stride_ * k + 72; }
  long base() const { return stride_ * n_; }
  /// Index into the value array of entry (r, c), r ≤ c, of the pattern.
  long slot(int r, int c) const {
    const int n6 = 6 * n_;
    if (r >= n6) return base() + static_cast<long>(r - n6) * nb_ + (c - n6);
    const int k = r / 6, a = r % 6;
    if (c >= n6) return border(k) + static_cast<long>(a) * nb_ + (c - n6);
    const int kc = c / 6, b = c % 6;
    return kc == k ? diag(k) + 6 * a + b : coupling(kc) + 6 * a + b;  // kc = k + 1
  }
  /// y = S x for the symmetric matrix whose upper triangle is `values`.
  void multiply(const std::vector<double>& values, const VecX& x, VecX& y) const;

  /// Compressed-column upper triangle (CHOLMOD): column pointers, row indices and, per entry, its
  /// slot in the value array. Built on first use.
  struct Csc {
    std::vector<long> colptr, rowind, slot;
  };
  const Csc& csc() const;

 private:
  int n_, nb_;
  long stride_;
  mutable std::once_flag csc_once_;
  mutable Csc csc_;
};

/// The symmetric matrix of a pattern's values, dense (tests and small systems).
MatX to_dense(const BorderedPattern& pattern, const std::vector<double>& values);

}  // namespace rfem
