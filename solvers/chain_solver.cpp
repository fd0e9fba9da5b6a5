#include "solvers/chain_solver.hpp"

#include <omp.h>

namespace rfem {

namespace {
using RowMat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
using Block = Eigen::Map<RowMat6>;
using CBlock = Eigen::Map<const RowMat6>;
using BorderMap = Eigen::Map<Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>>;
using CBorderMap = Eigen::Map<const Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>>;
}  // namespace

ChainSolver::ChainSolver(const BorderedPattern& pattern)
    : pattern_(pattern), n_(pattern.n_rfes()), nb_(pattern.n_base()), p_(n_ > 0 ? n_ / 2 : -1) {
  if (n_ > 0) {
    top_ = {0, p_, 1};                   // blocks 0 … p−1
    bottom_ = {n_ - 1, n_ - 1 - p_, -1};  // blocks n−1 … p+1
  }
}

// Block k's coupling to the block before it in the sweep, S(prev, k), stored at E_k (forward) or
// as E_{k+1}ᵀ (backward).
Mat6 ChainSolver::coupling(const double* v, int prev, int k) const {
  if (prev < k) return CBlock(v + pattern_.coupling(k));
  return CBlock(v + pattern_.coupling(prev)).transpose();
}

bool ChainSolver::sweep_factor(double* v, const Sweep& s, MatX& schur) const {
  schur.setZero(6 + nb_, 6 + nb_);
  if (s.count == 0) return true;
  // In place: D_k ← L_k (lower Cholesky factor), the coupling slot of k ← F_k = L_prev⁻¹ S(prev, k),
  // B_k ← W_k = L_k⁻¹ (B_k − F_kᵀ W_prev).
  int prev = -1;
  for (int i = 0; i < s.count; ++i) {
    const int k = s.first + i * s.step;
    Block D(v + pattern_.diag(k));
    Mat6 Dk = D.selfadjointView<Eigen::Upper>();
    BorderMap B(v + pattern_.border(k), 6, nb_);
    if (prev >= 0) {
      const Mat6 F = CBlock(v + pattern_.diag(prev)).triangularView<Eigen::Lower>().solve(coupling(v, prev, k));
      Block(v + factor_slot(prev, k)) = F;
      Dk.noalias() -= F.transpose() * F;
      if (nb_ > 0) B.noalias() -= F.transpose() * CBorderMap(v + pattern_.border(prev), 6, nb_);
    }
    Eigen::LLT<Mat6> llt(Dk);
    if (llt.info() != Eigen::Success) return false;
    D = llt.matrixL().toDenseMatrix();
    if (nb_ > 0) {
      D.triangularView<Eigen::Lower>().solveInPlace(B);
      schur.bottomRightCorner(nb_, nb_).noalias() += B.transpose() * B;
    }
    prev = k;
  }
  // The last block's coupling to the separator, eliminated: F_sep = L_last⁻¹ S(last, p).
  const Mat6 Fs = CBlock(v + pattern_.diag(prev)).triangularView<Eigen::Lower>().solve(coupling(v, p_, prev).transpose());
  Block(v + factor_slot(prev, p_)) = Fs;
  schur.topLeftCorner<6, 6>().noalias() += Fs.transpose() * Fs;
  if (nb_ > 0) {
    const MatX cross = Fs.transpose() * CBorderMap(v + pattern_.border(prev), 6, nb_);
    schur.topRightCorner(6, nb_) += cross;
    schur.bottomLeftCorner(nb_, 6) += cross.transpose();
  }
  return true;
}

bool ChainSolver::factorize(std::vector<double>& values) {
  values_ = nullptr;
  double* v = values.data();
  const int off = n_ > 0 ? 6 : 0, w = off + nb_;
  MatX Z(w, w);
  // The interface: block p and the base, less both sweeps' contributions.
  for (int j = 0; j < nb_; ++j)
    for (int i = 0; i <= j; ++i)
      Z(off + i, off + j) = Z(off + j, off + i) = v[pattern_.slot(6 * n_ + i, 6 * n_ + j)];
  if (n_ > 0) {
    Z.topLeftCorner<6, 6>() = CBlock(v + pattern_.diag(p_)).selfadjointView<Eigen::Upper>();
    if (nb_ > 0) {
      const CBorderMap B(v + pattern_.border(p_), 6, nb_);
      Z.topRightCorner(6, nb_) = B;
      Z.bottomLeftCorner(nb_, 6) = B.transpose();
    }
    bool ok[2] = {true, true};
    const Sweep* sw[2] = {&top_, &bottom_};
    MatX schur[2];
#pragma omp parallel for schedule(static, 1) num_threads(2) if (parallel_)
    for (int i = 0; i < 2; ++i) ok[i] = sweep_factor(v, *sw[i], schur[i]);
    if (!ok[0] || !ok[1]) return false;
    Z -= schur[0];  // fixed order: top, then bottom
    Z -= schur[1];
  }
  if (w > 0) {
    iface_.compute(Z);
    if (iface_.info() != Eigen::Success) return false;
  }
  values_ = v;
  return true;
}

void ChainSolver::sweep_forward(const Sweep& s, VecX& b, VecX& y_iface) const {
  y_iface.setZero(6 + nb_);
  if (s.count == 0) return;
  const double* v = values_;
  Vec6 prev_y = Vec6::Zero();
  int prev = -1;
  for (int i = 0; i < s.count; ++i) {
    const int k = s.first + i * s.step;
    Vec6 r = b.segment<6>(6 * k);
    if (prev >= 0) r.noalias() -= CBlock(v + factor_slot(prev, k)).transpose() * prev_y;
    CBlock(v + pattern_.diag(k)).triangularView<Eigen::Lower>().solveInPlace(r);
    b.segment<6>(6 * k) = r;
    if (nb_ > 0) y_iface.tail(nb_).noalias() += CBorderMap(v + pattern_.border(k), 6, nb_).transpose() * r;
    prev_y = r;
    prev = k;
  }
  y_iface.head<6>().noalias() += CBlock(v + factor_slot(prev, p_)).transpose() * prev_y;
}

void ChainSolver::sweep_backward(const Sweep& s, VecX& b, const VecX& x_iface) const {
  if (s.count == 0) return;
  const double* v = values_;
  int next = p_;  // the separator's solution is coupled through F_sep
  Vec6 x_next = x_iface.head<6>();
  for (int i = s.count - 1; i >= 0; --i) {
    const int k = s.first + i * s.step;
    Vec6 r = b.segment<6>(6 * k);
    r.noalias() -= CBlock(v + factor_slot(k, next)) * x_next;
    if (nb_ > 0) r.noalias() -= CBorderMap(v + pattern_.border(k), 6, nb_) * x_iface.tail(nb_);
    CBlock(v + pattern_.diag(k)).transpose().triangularView<Eigen::Upper>().solveInPlace(r);
    b.segment<6>(6 * k) = r;
    x_next = r;
    next = k;
  }
}

void ChainSolver::solve(VecX& b) const {
  const int off = n_ > 0 ? 6 : 0, w = off + nb_;
  if (w == 0) return;
  VecX rhs(w);
  if (n_ > 0) rhs.head<6>() = b.segment<6>(6 * p_);
  rhs.tail(nb_) = b.tail(nb_);
  if (n_ == 0) {
    b = iface_.solve(rhs);
    return;
  }
  VecX y[2];
  const Sweep* sw[2] = {&top_, &bottom_};
#pragma omp parallel for schedule(static, 1) num_threads(2) if (parallel_)
  for (int i = 0; i < 2; ++i) sweep_forward(*sw[i], b, y[i]);
  rhs -= y[0];
  rhs -= y[1];
  const VecX x = iface_.solve(rhs);
  b.segment<6>(6 * p_) = x.head<6>();
  b.tail(nb_) = x.tail(nb_);
#pragma omp parallel for schedule(static, 1) num_threads(2) if (parallel_)
  for (int i = 0; i < 2; ++i) sweep_backward(*sw[i], b, x);
}

}  // namespace rfem
