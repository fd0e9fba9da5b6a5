#pragma once
// Block Cholesky factorisation of the bordered block-tridiagonal matrix (assembly/pattern.hpp):
// chains of 6×6 diagonal blocks D_k with couplings E_k = S(k−1, k), each block bordered by its
// chain's border columns B_k = S(k, cols_c), and the dense border block Z.
//
// Every chain c is cut at a separator block p_c = first + count/2. Its blocks before p_c are
// eliminated from its first block towards p_c, those after p_c from its last block towards p_c —
// independent sweeps (two per chain) that run on two threads — each leaving a dense Schur
// contribution on its chain's interface (block p_c and the chain's border columns). The interface
// system (6 per chain + nb) is factorised densely. There is no fill beyond the blocks, so the work
// is O(n), the factor overwrites the matrix (no extra storage), and the arithmetic is the same for
// any thread count (bitwise-identical results).
// Per sweep block k with coupling P_k = S(previous, k):
//   U_k = chol(D_k − Fᵀ_k F_k),  F_k = U_{k−1}⁻ᵀ P_k,  W_k = U_k⁻ᵀ (B_k − F_kᵀ W_{k−1}),
// and the interface receives Σ W_kᵀ W_k (border) and the last block's coupling to p_c.
#include <memory>
#include <vector>

#include "linear_solver.hpp"

namespace rfem {

class ChainSolver : public LinearSolver {
 public:
  /// Throws std::invalid_argument for a null pattern.
  explicit ChainSolver(std::shared_ptr<const BorderedPattern> pattern);
  /// Factorises in place: `values` then holds the factor and must stay untouched until the next
  /// factorisation. Returns false if the matrix is not positive definite.
  bool factorize(std::vector<double>& values) override;
  /// Solves S x = b in place with the last successful factorisation.
  void solve(VecX& b) const override;
  /// With two or more threads the sweeps run concurrently.
  void set_threads(int threads) override { parallel_ = threads > 1 && pattern_.n_blocks() > 1; }

 private:
  struct Sweep {
    int chain = 0;
    int first = 0, count = 0, step = 1;  // blocks first, first + step, … (count of them)
    int sep = 0;                          // the chain's separator block
  };
  Mat6 coupling(const double* v, int prev, int k) const;
  // Where the factor's coupling between consecutive blocks a, b of a sweep is kept: the slot of
  // the coupling between them.
  long factor_slot(int a, int b) const { return pattern_.coupling(std::max(a, b)); }
  // The sweeps, with fixed-size kernels for border widths W = 0 … 12 (Eigen::Dynamic otherwise):
  // the per-block products are small, and unrolled ones cost a fraction of general ones.
  bool sweep_factor(double* v, const Sweep& s, MatX& schur) const;
  void sweep_forward(const Sweep& s, VecX& b, VecX& y_iface) const;
  void sweep_backward(const Sweep& s, VecX& b, const VecX& x_iface) const;
  template <int W>
  bool sweep_factor_w(double* v, const Sweep& s, MatX& schur) const;
  template <int W>
  void sweep_forward_w(const Sweep& s, VecX& b, VecX& y_iface) const;
  template <int W>
  void sweep_backward_w(const Sweep& s, VecX& b, const VecX& x_iface) const;
  // Interface index of entry i of chain c's Schur contribution (its separator, then its columns).
  int iface_index(int c, int i) const;
  // The chain's part of the interface vector x (separator, then columns).
  VecX gather(int c, const VecX& x) const;

  std::shared_ptr<const BorderedPattern> shared_;
  const BorderedPattern& pattern_;  // *shared_
  int nb_, nc_;  // border width, chains
  std::vector<Sweep> sweeps_;  // two per chain: towards the separator from either end
  Eigen::LLT<MatX> iface_;
  const double* values_ = nullptr;  // the factor (the caller's array)
  bool parallel_ = false;
};

}  // namespace rfem
