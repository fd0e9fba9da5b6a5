#pragma once
// Block Cholesky factorisation of the bordered block-tridiagonal matrix of one flexible link
// (assembly/pattern.hpp): n diagonal 6×6 blocks D_k, off-diagonal blocks E_k = S(k−1, k), a dense
// border B_k = S(k, base) of nb columns and the base block Z.
//
// The chain is cut at a separator block p = n/2. Blocks 0 … p−1 are eliminated from the clamped
// end towards p, blocks n−1 … p+1 from the free end towards p — two independent sweeps that run on
// two threads — each leaving a dense Schur contribution on the interface (block p and the base).
// The (6 + nb) interface system is factorised densely. There is no fill beyond the blocks, so the
// work is O(n), the factor overwrites the matrix (no extra storage), and the arithmetic is the same
// for any thread count (bitwise-identical results).
// Per sweep block k with coupling P_k = S(previous, k):
//   U_k = chol(D_k − Fᵀ_k F_k),  F_k = U_{k−1}⁻ᵀ P_k,  W_k = U_k⁻ᵀ (B_k − F_kᵀ W_{k−1}),
// and the interface receives Σ W_kᵀ W_k (base) and the last block's coupling to p.
#include <vector>

#include "solvers/linear_solver.hpp"

namespace rfem {

class ChainSolver : public LinearSolver {
 public:
  explicit ChainSolver(const BorderedPattern& pattern);
  /// Factorises in place: `values` then holds the factor and must stay untouched until the next
  /// factorisation. Returns false if the matrix is not positive definite.
  bool factorize(std::vector<double>& values) override;
  /// Solves S x = b in place with the last successful factorisation.
  void solve(VecX& b) const override;
  /// With two or more threads the two sweeps run concurrently.
  void set_threads(int threads) override { parallel_ = threads > 1 && n_ > 1; }

 private:
  struct Sweep {
    int first = 0, count = 0, step = 1;  // blocks first, first + step, … (count of them)
  };
  Mat6 coupling(const double* v, int prev, int k) const;
  // Where the factor's coupling between consecutive blocks a, b of a sweep is kept: the slot of
  // the coupling between them.
  long factor_slot(int a, int b) const { return pattern_.coupling(std::max(a, b)); }
  bool sweep_factor(double* v, const Sweep& s, MatX& schur) const;
  void sweep_forward(const Sweep& s, VecX& b, VecX& y_iface) const;
  void sweep_backward(const Sweep& s, VecX& b, const VecX& x_iface) const;

  const BorderedPattern& pattern_;
  int n_, nb_, p_;  // rfes, border width, separator block (−1 if n = 0)
  Sweep top_, bottom_;
  Eigen::LLT<MatX> iface_;
  const double* values_ = nullptr;  // the factor (the caller's array)
  bool parallel_ = false;
};

}  // namespace rfem
