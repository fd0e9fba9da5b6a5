#include "solvers/newton_system.hpp"

namespace rfem {

NewtonSystem::NewtonSystem(const Model& model, std::vector<int> base_col, int nb, LinearSolverKind kind,
                           Workspace* ws, bool keep_stiffness)
    : model_(model),
      ws_(ws ? *ws : own_),
      base_col_(std::move(base_col)),
      pattern_(model.n(), nb),
      solver_(make_linear_solver(kind, pattern_)),
      damped_(model.link.damping_beta != 0.0),
      keep_stiffness_(keep_stiffness) {}

bool NewtonSystem::setup(const VecX& q, const VecX& v, double h) {
  MatrixTerms terms;
  terms.mass = 1.0;
  terms.damping = h;
  terms.stiffness = h * h;
  std::vector<SdeTarget> extra;
  if (keep_stiffness_) extra.push_back({&K_, 1.0, 0.0});
  if (damped_) extra.push_back({&C_, 0.0, 1.0});
  assemble_matrices(model_, pattern_, base_col_, q, v, terms, S_, extra, &base_rows_, &ws_);
  h_ = h;
  solver_->set_threads(ws_.parallel.team(model_.n()));
  return solver_->factorize(S_);
}

void NewtonSystem::solve(VecX& b) const {
  solver_->set_threads(ws_.parallel.team(model_.n()));
  solver_->solve(b);
}

void NewtonSystem::damping_times(const VecX& x, VecX& y) const {
  if (!damped_) {
    y.setZero(x.size());
    return;
  }
  pattern_.multiply(C_, x, y);
}

void NewtonSystem::solve_bdf(const double* b, double* x) const {
  const int u = size();
  const double c = 1.0 / h_;
  VecX Kb1;
  pattern_.multiply(K_, Eigen::Map<const VecX>(b, u), Kb1);
  VecX rhs = c * Eigen::Map<const VecX>(b + u, u) - Kb1;
  solve(rhs);  // S(h) = h² (c² M + c C + K): x2 = S⁻¹ rhs / c²
  rhs *= h_ * h_;
  for (int i = 0; i < u; ++i) {
    x[u + i] = rhs[i];
    x[i] = (b[i] + rhs[i]) * h_;
  }
}

}  // namespace rfem
