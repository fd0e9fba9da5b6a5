#include "solvers/newton_system.hpp"

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

bool NewtonSystem::setup_mass(const VecX& q, const VecX& v) {
  MatrixTerms mt;
  mt.mass = 1.0;
  assemble_matrix(model_, pattern_, base_col_, q, v, mt, S_);
  return solver_.factorize(S_);
}

void NewtonSystem::stiffness_times(const double* x, double* y) const {
  const auto& cp = pattern_.colptr();
  const auto& ri = pattern_.rowind();
  const int N = pattern_.size();
  std::fill(y, y + N, 0.0);
  for (int c = 0; c < N; ++c)
    for (long k = cp[c]; k < cp[c + 1]; ++k) {
      const long r = ri[k];
      y[r] += K_[k] * x[c];
      if (r != c) y[c] += K_[k] * x[r];
    }
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
