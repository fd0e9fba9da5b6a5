#include "newton_system.hpp"
#include "../core/check.hpp"

#include <stdexcept>

#include "mass_solve.hpp"

namespace rfem {

NewtonSystem::NewtonSystem(std::shared_ptr<const Model> model, std::vector<int> base_col, LinearSolverKind kind,
                           bool keep_stiffness, std::shared_ptr<const Reduction> reduction)
    : model_(model ? std::move(model) : throw std::invalid_argument("NewtonSystem: no model")),
      base_col_(std::move(base_col)),
      pattern_(std::make_shared<const BorderedPattern>(*model_, base_col_)),
      solver_(reduction ? nullptr : make_linear_solver(kind, pattern_)),
      reduction_(std::move(reduction)),
      damped_(model_->sdes_damped()),
      keep_stiffness_(keep_stiffness) {
  if (reduction_) {
    P_ = reduction_->projector(pattern_->size() - model_->flexible_dofs());
    reduced_ = std::make_unique<ReducedFactor>();
    projection_ = std::make_unique<Projection>(*reduction_, *pattern_);
  }
}

bool NewtonSystem::setup(const VecX& q, const VecX& v, double h, Workspace& ws) {
  MatrixTerms terms;
  terms.mass = 1.0;
  terms.damping = h;
  terms.stiffness = h * h;
  std::vector<SdeTarget> extra;
  if (keep_stiffness_) extra.push_back({&K_, 1.0, 0.0});
  if (damped_) extra.push_back({&C_, 0.0, 1.0});
  assemble_matrices(*model_, *pattern_, base_col_, q, v, terms, S_, extra, &base_rows_, &ws);
  const int nb = pattern_->n_base(), first = nb - static_cast<int>(kp_.size());  // unknown joints end the border
  for (int c = 0; c < static_cast<int>(kp_.size()); ++c) {
    const long d = pattern_->base() + static_cast<long>(first + c) * nb + first + c;
    S_[d] += h * kd_[c] + h * h * kp_[c];
    if (keep_stiffness_) K_[d] += kp_[c];
  }
  h_ = h;
  if (reduction_) {
    const int team = ws.parallel.team(model_->n());
    if (keep_stiffness_) Kr_ = projection_->reduce(K_, team);
    if (damped_) Cr_ = projection_->reduce(C_, team);
    {  // the joints' rows over the reduced unknowns: each row projected as a residual is (Pᵀ row)
      const int k = pattern_->size() - model_->flexible_dofs();
      MatX reduced(base_rows_.rows(), P_.cols());
      VecX row, out(P_.cols());
      for (long i = 0; i < base_rows_.rows(); ++i) {
        row = base_rows_.row(i).transpose();
        reduction_->project(row.data(), out.data(), k, team);
        reduced.row(i) = out.transpose();
      }
      base_rows_ = std::move(reduced);
    }
    return reduced_->factorize(projection_->reduce(S_, team), reduction_->kept(), true, team);
  }
  solver_->set_threads(ws.parallel.team(model_->n()));
  return solver_->factorize(S_);
}

bool NewtonSystem::solve_mass(const VecX& q, const VecX& v, VecX& b, std::vector<double>& values, Workspace& ws) const {
  RFEM_CHECK_ARGUMENT_SIZE(b.size(), size(), "b");
  if (!reduction_) return rfem::solve_mass(*model_, *pattern_, base_col_, q, v, b, values, &ws);
  MatrixTerms mt;
  mt.mass = 1.0;
  assemble_matrices(*model_, *pattern_, base_col_, q, v, mt, values, {}, nullptr, &ws);
  ReducedFactor f;
  if (!f.factorize(projection_->reduce(values), reduction_->kept())) return false;
  f.solve(b);
  return true;
}

void NewtonSystem::set_joint_feedback(std::vector<double> kp, std::vector<double> kd) {
  int unknown_joints = 0;
  for (int c : base_col_) unknown_joints += c >= 0;
  if (static_cast<int>(kp.size()) != unknown_joints || kd.size() != kp.size())
    throw std::invalid_argument("one feedback gain pair per unknown joint is required");
  kp_ = std::move(kp);
  kd_ = std::move(kd);
}

void NewtonSystem::solve(VecX& b, int threads) const {
  if (reduced_) {
    reduced_->solve(b, threads);
    return;
  }
  solver_->set_threads(threads);
  solver_->solve(b);
}

void NewtonSystem::damping_times(const VecX& x, VecX& y) const {
  if (!damped_) {
    y.setZero(x.size());
    return;
  }
  if (reduction_) y = Cr_ * x;
  else pattern_->multiply(C_, x, y);
}

void NewtonSystem::solve_bdf(const double* b, double* x, int threads) const {
  RFEM_CHECK_ARGUMENT(b != nullptr && x != nullptr, "b and x must point to 2 × size() values");
  RFEM_CHECK_ARGUMENT(h_ > 0, "no Newton matrix: call setup() first");
  const int u = size();
  const double c = 1.0 / h_;
  VecX Kb1;
  if (reduction_) Kb1 = Kr_ * Eigen::Map<const VecX>(b, u);
  else pattern_->multiply(K_, Eigen::Map<const VecX>(b, u), Kb1);
  VecX rhs = c * Eigen::Map<const VecX>(b + u, u) - Kb1;
  solve(rhs, threads);  // S(h) = h² (c² M + c C + K): x2 = S⁻¹ rhs / c²
  rhs *= h_ * h_;
  for (int i = 0; i < u; ++i) {
    x[u + i] = rhs[i];
    x[i] = (b[i] + rhs[i]) * h_;
  }
}

}  // namespace rfem
