#pragma once
// Storage of the bordered block matrix of the Newton system (docs/formulation.md §4), its upper
// triangle block by block. The unknowns are 6-blocks (rfes) grouped into *chains* — runs of
// consecutive blocks, each coupled to its neighbours (the rfes of one link between carrying rfes)
// — followed by nb *border* coordinates (carrying rfes and unknown joints). Every block of chain c
// is coupled to the same set of border columns cols_c (what its link's rfes depend on). Per block k
// of chain c (stride 72 + 6 w_c, w_c = |cols_c|):
//   D_k = S(k, k)     6×6, row-major (its upper triangle is the matrix; the lower is scratch),
//   E_k = S(k−1, k)   6×6, row-major (rows of block k−1; unused for a chain's first block),
//   B_k = S(k, cols_c) 6×w_c, row-major,
// then the border block Z (nb×nb, row-major, upper triangle). Eliminating a chain only updates
// Z on cols_c × cols_c, which is dense anyway: the Cholesky factor has no fill beyond these blocks
// in this order, so the chain solver factorises in place, and CHOLMOD receives the same entries
// in compressed columns (built on first use).
#include <mutex>
#include <vector>

#include "../core/model.hpp"

namespace rfem {

class BorderedPattern {
 public:
  struct Chain {
    int first = 0, count = 0;  ///< blocks first … first + count − 1
    std::vector<int> cols;     ///< border columns of its blocks, ascending
  };
  /// One chain of n blocks bordered by all nb columns (one flexible link at the end of a chain).
  BorderedPattern(int n_blocks, int n_base);
  /// Chains covering blocks 0 … N−1 in order, and nb border columns.
  BorderedPattern(std::vector<Chain> chains, int n_base);
  /// The Newton matrix over a model's unknowns, numbered as EquationsOfMotion does: every rfe
  /// coordinate in the model's order, then the joints with base_col[j] ≥ 0 (in that order). The
  /// chains are each link's runs of rfes that carry nothing; the border holds the carrying rfes and
  /// the unknown joints; a chain's columns are the unknown nodes that move its link and the
  /// carrying rfes at its ends.
  BorderedPattern(const Model& model, const std::vector<int>& base_col);

  int n_blocks() const { return nblocks_; }
  int n_base() const { return nb_; }
  int size() const { return 6 * nblocks_ + nb_; }
  const std::vector<Chain>& chains() const { return chains_; }
  int chain_of(int k) const { return chain_of_[k]; }
  /// Border width of block k.
  int width(int k) const { return static_cast<int>(chains_[chain_of_[k]].cols.size()); }
  /// Whether block k is coupled to block k − 1 (the same chain).
  bool coupled(int k) const { return k > 0 && chain_of_[k] == chain_of_[k - 1]; }
  /// Position of border column `col` among block k's border columns, −1 if not coupled.
  int border_pos(int k, int col) const { return pos_[chain_of_[k]][col]; }
  /// Values to store (the storage size, not the count of distinct entries).
  long nnz() const { return base() + static_cast<long>(nb_) * nb_; }
  /// Distinct entries of the upper triangle.
  long entries() const;
  long diag(int k) const { return offset_[k]; }
  long coupling(int k) const { return offset_[k] + 36; }
  long border(int k) const { return offset_[k] + 72; }
  /// Values of block k (D, E and B): slots diag(k) … diag(k) + block_size(k) − 1.
  long block_size(int k) const { return offset_[k + 1] - offset_[k]; }
  long base() const { return offset_[nblocks_]; }
  /// Index into the value array of entry (r, c), r ≤ c, of the pattern; −1 if (r, c) is outside it.
  long slot(int r, int c) const;
  /// y = S x for the symmetric matrix whose upper triangle is `values`.
  void multiply(const std::vector<double>& values, const VecX& x, VecX& y) const;

  /// Compressed-column upper triangle (CHOLMOD): column pointers, row indices and, per entry, its
  /// slot in the value array. Built on first use.
  struct Csc {
    std::vector<long> colptr, rowind, slot;
  };
  const Csc& csc() const;

 private:
  void index();
  std::vector<Chain> chains_;
  int nblocks_ = 0, nb_ = 0;
  std::vector<int> chain_of_;
  std::vector<long> offset_;          // per block, then the border block's
  std::vector<std::vector<int>> pos_;  // per chain: border column → position (−1)
  mutable std::once_flag csc_once_;
  mutable Csc csc_;
};

/// The symmetric matrix of a pattern's values, dense (tests and small systems).
MatX to_dense(const BorderedPattern& pattern, const std::vector<double>& values);

}  // namespace rfem
