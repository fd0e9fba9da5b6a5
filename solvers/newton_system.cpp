#include "solvers/newton_system.hpp"

#include <Eigen/SparseCore>

namespace rfem {

NewtonSystem::NewtonSystem(const Model& model, std::vector<int> base_col, int nb)
    : model_(model), base_col_(std::move(base_col)), pattern_(model.n(), nb), solver_(pattern_) {}

bool NewtonSystem::setup(const VecX& q, const VecX& v, double c) {
  MatrixTerms terms;
  terms.mass = c * c;
  terms.damping = c;
  terms.stiffness = 1.0;
  assemble_matrix(model_, pattern_, base_col_, q, v, terms, S_, &K_);
  c_ = c;
  return solver_.factorize(S_);
}

void NewtonSystem::stiffness_times(const double* x, double* y) const {
  // The stored upper triangle as an Eigen sparse view: its symmetric product is vectorised.
  const int N = pattern_.size();
  const Eigen::Map<const Eigen::SparseMatrix<double, Eigen::ColMajor, long>> K(
      N, N, pattern_.nnz(), pattern_.colptr().data(), pattern_.rowind().data(), K_.data());
  Eigen::Map<VecX>(y, N).noalias() = K.selfadjointView<Eigen::Upper>() * Eigen::Map<const VecX>(x, N);
}

void NewtonSystem::solve(const double* b, double* x) const {
  const int u = size();
  VecX Kb1(u);
  stiffness_times(b, Kb1.data());
  VecX rhs = c_ * Eigen::Map<const VecX>(b + u, u) - Kb1;
  solver_.solve(rhs);
  for (int i = 0; i < u; ++i) {
    x[u + i] = rhs[i];
    x[i] = (b[i] + rhs[i]) / c_;
  }
}

}  // namespace rfem
