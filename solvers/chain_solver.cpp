#include "chain_solver.hpp"

#include <omp.h>

#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "../core/check.hpp"

namespace rfem {

namespace {
using RowMat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
using Block = Eigen::Map<RowMat6>;
using CBlock = Eigen::Map<const RowMat6>;
}  // namespace

ChainSolver::ChainSolver(std::shared_ptr<const BorderedPattern> pattern)
    : shared_(pattern ? std::move(pattern) : throw std::invalid_argument("ChainSolver: no pattern")),
      pattern_(*shared_),
      nb_(pattern_.n_base()),
      nc_(static_cast<int>(pattern_.chains().size())) {
  for (int c = 0; c < nc_; ++c) {
    const BorderedPattern::Chain& ch = pattern_.chains()[c];
    const int half = ch.count / 2, p = ch.first + half, last = ch.first + ch.count - 1;
    sweeps_.push_back({c, ch.first, half, 1, p});            // blocks first … p−1
    sweeps_.push_back({c, last, ch.count - 1 - half, -1, p});  // blocks last … p+1
  }
}

int ChainSolver::iface_index(int c, int i) const {
  return i < 6 ? 6 * c + i : 6 * nc_ + pattern_.chains()[c].cols[i - 6];
}

VecX ChainSolver::gather(int c, const VecX& x) const {
  const std::vector<int>& cols = pattern_.chains()[c].cols;
  VecX out(6 + cols.size());
  out.head<6>() = x.segment<6>(6 * c);
  for (size_t i = 0; i < cols.size(); ++i) out[6 + i] = x[6 * nc_ + cols[i]];
  return out;
}

// Block k's coupling to the block before it in the sweep, S(prev, k), stored at E_k (forward) or
// as E_{k+1}ᵀ (backward).
Mat6 ChainSolver::coupling(const double* v, int prev, int k) const {
  if (prev < k) return CBlock(v + pattern_.coupling(k));
  return CBlock(v + pattern_.coupling(prev)).transpose();
}

namespace {
// Calls f(std::integral_constant<int, W>) with W = w for 0 ≤ w ≤ 12, else W = Eigen::Dynamic (0: a chain
// with no border columns, every joint prescribed).
template <class F>
decltype(auto) with_width(int w, F&& f) {
  switch (w) {
#define RFEM_WIDTH(n) \
  case n:             \
    return f(std::integral_constant<int, n>{});
    RFEM_WIDTH(0) RFEM_WIDTH(1) RFEM_WIDTH(2) RFEM_WIDTH(3) RFEM_WIDTH(4) RFEM_WIDTH(5) RFEM_WIDTH(6)
    RFEM_WIDTH(7) RFEM_WIDTH(8) RFEM_WIDTH(9) RFEM_WIDTH(10) RFEM_WIDTH(11) RFEM_WIDTH(12)
#undef RFEM_WIDTH
    default:
      return f(std::integral_constant<int, Eigen::Dynamic>{});
  }
}
// 6 × W row-major (a 6 × 1 border is a column: the same layout, Eigen wants it column-major).
template <int W>
using BorderMatrix = Eigen::Matrix<double, 6, W, W == 1 ? Eigen::ColMajor : Eigen::RowMajor>;
template <int W>
using BorderW = Eigen::Map<BorderMatrix<W>>;
template <int W>
using CBorderW = Eigen::Map<const BorderMatrix<W>>;

// The 6×6 factors are kept as L with its diagonal inverted (row-major), so the substitutions below
// multiply where Eigen's general triangular solvers would divide, and unroll for fixed sizes.
// Lower Cholesky factor of the symmetric A into L (diagonal inverted); false unless positive definite.
bool cholesky6(const Mat6& A, double* L) {
  for (int j = 0; j < 6; ++j) {
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= L[6 * j + k] * L[6 * j + k];
    if (!(d > 0.0)) return false;  // also NaN
    const double inv = 1.0 / std::sqrt(d);
    L[7 * j] = inv;
    for (int i = j + 1; i < 6; ++i) {
      double a = A(i, j);
      for (int k = 0; k < j; ++k) a -= L[6 * i + k] * L[6 * j + k];
      L[6 * i + j] = a * inv;
    }
    for (int i = 0; i < j; ++i) L[6 * i + j] = 0.0;
  }
  return true;
}
// X ← L⁻¹ X (X has 6 rows).
template <class M>
void lower_solve(const double* L, M& X) {
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < i; ++k) X.row(i) -= L[6 * i + k] * X.row(k);
    X.row(i) *= L[7 * i];
  }
}
// X ← L⁻ᵀ X.
template <class M>
void upper_solve(const double* L, M& X) {
  for (int i = 5; i >= 0; --i) {
    for (int k = i + 1; k < 6; ++k) X.row(i) -= L[6 * k + i] * X.row(k);
    X.row(i) *= L[7 * i];
  }
}
}  // namespace

bool ChainSolver::sweep_factor(double* v, const Sweep& s, MatX& schur) const {
  const int w = static_cast<int>(pattern_.chains()[s.chain].cols.size());
  return with_width(w, [&](auto W) { return sweep_factor_w<decltype(W)::value>(v, s, schur); });
}
void ChainSolver::sweep_forward(const Sweep& s, VecX& b, VecX& y) const {
  const int w = static_cast<int>(pattern_.chains()[s.chain].cols.size());
  with_width(w, [&](auto W) { sweep_forward_w<decltype(W)::value>(s, b, y); });
}
void ChainSolver::sweep_backward(const Sweep& s, VecX& b, const VecX& x) const {
  const int w = static_cast<int>(pattern_.chains()[s.chain].cols.size());
  with_width(w, [&](auto W) { sweep_backward_w<decltype(W)::value>(s, b, x); });
}

template <int W>
bool ChainSolver::sweep_factor_w(double* v, const Sweep& s, MatX& schur) const {
  const int w = static_cast<int>(pattern_.chains()[s.chain].cols.size());
  schur.setZero(6 + w, 6 + w);
  if (s.count == 0) return true;
  Eigen::Matrix<double, W, W> acc = Eigen::Matrix<double, W, W>::Zero(w, w);  // Σ W_kᵀ W_k
  // In place: D_k ← L_k (lower Cholesky factor, diagonal inverted), the coupling slot of k ← F_k = L_prev⁻¹ S(prev, k),
  // B_k ← W_k = L_k⁻¹ (B_k − F_kᵀ W_prev).
  int prev = -1;
  for (int i = 0; i < s.count; ++i) {
    const int k = s.first + i * s.step;
    double* L = v + pattern_.diag(k);
    Mat6 Dk = Block(L).selfadjointView<Eigen::Upper>();
    BorderW<W> B(v + pattern_.border(k), 6, w);
    if (prev >= 0) {
      Mat6 F = coupling(v, prev, k);
      lower_solve(v + pattern_.diag(prev), F);
      Block(v + factor_slot(prev, k)) = F;
      Dk.noalias() -= F.transpose() * F;
      if (w > 0) B.noalias() -= F.transpose() * CBorderW<W>(v + pattern_.border(prev), 6, w);
    }
    if (!cholesky6(Dk, L)) return false;
    if (w > 0) {
      lower_solve(L, B);
      acc.noalias() += B.transpose() * B;
    }
    prev = k;
  }
  schur.bottomRightCorner(w, w) = acc;
  // The last block's coupling to the separator, eliminated: F_sep = L_last⁻¹ S(last, p).
  Mat6 Fs = coupling(v, s.sep, prev).transpose();
  lower_solve(v + pattern_.diag(prev), Fs);
  Block(v + factor_slot(prev, s.sep)) = Fs;
  schur.topLeftCorner<6, 6>().noalias() += Fs.transpose() * Fs;
  if (w > 0) {
    const Eigen::Matrix<double, 6, W> cross = Fs.transpose() * CBorderW<W>(v + pattern_.border(prev), 6, w);
    schur.topRightCorner(6, w) += cross;
    schur.bottomLeftCorner(w, 6) += cross.transpose();
  }
  return true;
}

bool ChainSolver::factorize(std::vector<double>& values) {
  RFEM_CHECK_ARGUMENT_SIZE(values.size(), pattern_.nnz(), "values");
  values_ = nullptr;
  double* v = values.data();
  const int off = 6 * nc_, size = off + nb_;
  MatX Z(size, size);
  // The interface: every chain's separator block and the border, less the sweeps' contributions.
  for (int j = 0; j < nb_; ++j)
    for (int i = 0; i <= j; ++i) Z(off + i, off + j) = Z(off + j, off + i) = v[pattern_.base() + static_cast<long>(i) * nb_ + j];
  if (nc_ > 0) {
    for (int c = 0; c < nc_; ++c) {
      const int p = sweeps_[2 * c].sep;
      const std::vector<int>& cols = pattern_.chains()[c].cols;
      Z.block<6, 6>(6 * c, 6 * c) = CBlock(v + pattern_.diag(p)).selfadjointView<Eigen::Upper>();
      for (int d = 0; d < nc_; ++d)
        if (d != c) Z.block<6, 6>(6 * c, 6 * d).setZero();
      for (int i = 0; i < nb_; ++i) Z.block<6, 1>(6 * c, off + i).setZero();
      const CBorderW<Eigen::Dynamic> B(v + pattern_.border(p), 6, static_cast<long>(cols.size()));
      for (size_t i = 0; i < cols.size(); ++i) Z.block<6, 1>(6 * c, off + cols[i]) = B.col(static_cast<long>(i));
      Z.block(off, 6 * c, nb_, 6) = Z.block(6 * c, off, 6, nb_).transpose();
    }
    const int ns = static_cast<int>(sweeps_.size());
    std::vector<char> ok(ns, 1);
    std::vector<MatX> schur(ns);
#pragma omp parallel for schedule(static, 1) num_threads(2) if (parallel_)
    for (int i = 0; i < ns; ++i) ok[i] = sweep_factor(v, sweeps_[i], schur[i]);
    for (int i = 0; i < ns; ++i)
      if (!ok[i]) return false;
    for (int i = 0; i < ns; ++i) {  // fixed order: chain by chain, top, then bottom
      const int c = sweeps_[i].chain, w = static_cast<int>(schur[i].rows());
      for (int b = 0; b < w; ++b)
        for (int a = 0; a < w; ++a) Z(iface_index(c, a), iface_index(c, b)) -= schur[i](a, b);
    }
  }
  if (size > 0) {
    iface_.compute(Z);
    if (iface_.info() != Eigen::Success) return false;
  }
  values_ = v;
  return true;
}

template <int W>
void ChainSolver::sweep_forward_w(const Sweep& s, VecX& b, VecX& y_iface) const {
  const int w = static_cast<int>(pattern_.chains()[s.chain].cols.size());
  y_iface.setZero(6 + w);
  if (s.count == 0) return;
  const double* v = values_;
  Eigen::Matrix<double, W, 1> y = Eigen::Matrix<double, W, 1>::Zero(w);
  Vec6 prev_y = Vec6::Zero();
  int prev = -1;
  for (int i = 0; i < s.count; ++i) {
    const int k = s.first + i * s.step;
    Vec6 r = b.segment<6>(6 * k);
    if (prev >= 0) r.noalias() -= CBlock(v + factor_slot(prev, k)).transpose() * prev_y;
    lower_solve(v + pattern_.diag(k), r);
    b.segment<6>(6 * k) = r;
    if (w > 0) y.noalias() += CBorderW<W>(v + pattern_.border(k), 6, w).transpose() * r;
    prev_y = r;
    prev = k;
  }
  y_iface.tail(w) = y;
  y_iface.head<6>().noalias() += CBlock(v + factor_slot(prev, s.sep)).transpose() * prev_y;
}

template <int W>
void ChainSolver::sweep_backward_w(const Sweep& s, VecX& b, const VecX& x_iface) const {
  if (s.count == 0) return;
  const int w = static_cast<int>(x_iface.size()) - 6;
  const double* v = values_;
  const Eigen::Matrix<double, W, 1> xb = x_iface.tail(w);
  int next = s.sep;  // the separator's solution is coupled through F_sep
  Vec6 x_next = x_iface.head<6>();
  for (int i = s.count - 1; i >= 0; --i) {
    const int k = s.first + i * s.step;
    Vec6 r = b.segment<6>(6 * k);
    r.noalias() -= CBlock(v + factor_slot(k, next)) * x_next;
    if (w > 0) r.noalias() -= CBorderW<W>(v + pattern_.border(k), 6, w) * xb;
    upper_solve(v + pattern_.diag(k), r);
    b.segment<6>(6 * k) = r;
    x_next = r;
    next = k;
  }
}

void ChainSolver::solve(VecX& b) const {
  RFEM_CHECK_ARGUMENT_SIZE(b.size(), pattern_.size(), "b");
  const int n6 = 6 * pattern_.n_blocks(), off = 6 * nc_, size = off + nb_;
  if (size == 0) return;
  if (!values_) throw std::logic_error("ChainSolver::solve without a successful factorisation");
  VecX rhs(size);
  for (int c = 0; c < nc_; ++c) rhs.segment<6>(6 * c) = b.segment<6>(6 * sweeps_[2 * c].sep);
  rhs.tail(nb_) = b.tail(nb_);
  if (nc_ == 0) {
    b = iface_.solve(rhs);
    return;
  }
  const int ns = static_cast<int>(sweeps_.size());
  std::vector<VecX> y(ns);
#pragma omp parallel for schedule(static, 1) num_threads(2) if (parallel_)
  for (int i = 0; i < ns; ++i) sweep_forward(sweeps_[i], b, y[i]);
  for (int i = 0; i < ns; ++i)  // fixed order
    for (int a = 0; a < y[i].size(); ++a) rhs[iface_index(sweeps_[i].chain, a)] -= y[i][a];
  const VecX x = iface_.solve(rhs);
  for (int c = 0; c < nc_; ++c) b.segment<6>(6 * sweeps_[2 * c].sep) = x.segment<6>(6 * c);
  b.segment(n6, nb_) = x.tail(nb_);
  std::vector<VecX> xc(nc_);
  for (int c = 0; c < nc_; ++c) xc[c] = gather(c, x);
#pragma omp parallel for schedule(static, 1) num_threads(2) if (parallel_)
  for (int i = 0; i < ns; ++i) sweep_backward(sweeps_[i], b, xc[sweeps_[i].chain]);
}

}  // namespace rfem
