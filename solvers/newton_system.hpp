#pragma once
// The Newton matrix of the time integrators on the unknowns' bordered pattern,
//   S(h) = M + h C + h² K,
// with M the mass matrix, C the sde damping and K the sde stiffness (with its geometric term): the
// symmetric positive definite part of ∂r/∂a + h ∂r/∂v + h² ∂r/∂q. Assembled in one pass at a
// state and factorised by the chosen LinearSolver (the chain solver in place: S costs one array).
//
// For IDA (c = c_j = 1/h) the 2N system [c I, −I; K, C + c M] [x1; x2] = [b1; b2] is solved
// through its Schur complement: (c² M + c C + K) x2 = c b2 − K b1, x1 = (b1 + x2)/c; K is then
// kept as well.
//
// With reduced links (solvers/reduction.hpp) S is assembled over every coordinate as above and
// projected, S_r = Pᵀ S P (small: the kept modes), and factorised by a sparse Cholesky; every
// vector of the methods below is then over the reduced unknowns.
//
// The system shares its model and owns its pattern, solver and values; the caller's workspace
// (thread policy and scratch) is an argument of setup(). Movable, not copyable.
#include <memory>

#include "../assembly/assemble.hpp"
#include "linear_solver.hpp"
#include "reduction.hpp"

namespace rfem {

class NewtonSystem {
 public:
  /// base_col[j]: joint j's column among the unknowns (numbered after the 6n rfe coordinates), −1
  /// if prescribed. `keep_stiffness`: keep K (IDA's solve). Throws std::invalid_argument for a
  /// null model or a base_col that does not fit it.
  NewtonSystem(std::shared_ptr<const Model> model, std::vector<int> base_col,
               LinearSolverKind kind = LinearSolverKind::Chain, bool keep_stiffness = false,
               std::shared_ptr<const Reduction> reduction = nullptr);
  NewtonSystem(NewtonSystem&&) noexcept = default;
  NewtonSystem& operator=(NewtonSystem&&) noexcept = default;
  NewtonSystem(const NewtonSystem&) = delete;
  NewtonSystem& operator=(const NewtonSystem&) = delete;

  /// Stiffness and damping a feedback law adds on the unknown joints' diagonal (one per unknown
  /// joint, in column order): S gains h kd + h² kp, IDA's K gains kp.
  void set_joint_feedback(std::vector<double> kp, std::vector<double> kd);
  /// Assembles S(h) at a state (full coordinates) with the workspace's thread policy and scratch
  /// and factorises it. False if not positive definite.
  bool setup(const VecX& q, const VecX& v, double h, Workspace& ws);
  /// Solves S(h) x = b in place (the h of the last setup) on up to `threads` threads.
  void solve(VecX& b, int threads = 1) const;
  /// IDA's system for x = [x1; x2] (2·size()) given b, with c = 1/h of the last setup.
  void solve_bdf(const double* b, double* x, int threads = 1) const;
  double h() const { return h_; }
  /// Unknowns: the pattern's, or the reduced ones.
  int size() const { return reduction_ ? static_cast<int>(P_.cols()) : pattern_->size(); }
  const BorderedPattern& pattern() const { return *pattern_; }
  /// Solves M b' = b in place with the mass matrix at (q, v) (full coordinates); `values` is scratch.
  /// False if M is not positive definite.
  bool solve_mass(const VecX& q, const VecX& v, VecX& b, std::vector<double>& values, Workspace& ws) const;
  /// Rows of every joint of M over the unknowns (m × size()), at the last setup.
  const MatX& base_rows() const { return base_rows_; }
  /// y = C x with the sde damping of the last setup (zero if undamped).
  void damping_times(const VecX& x, VecX& y) const;

 private:
  std::shared_ptr<const Model> model_;
  std::vector<int> base_col_;
  std::shared_ptr<const BorderedPattern> pattern_;
  std::unique_ptr<LinearSolver> solver_;
  std::vector<double> S_, K_, C_, kp_, kd_;
  MatX base_rows_;
  std::shared_ptr<const Reduction> reduction_;
  SparseMat P_, Kr_, Cr_;  // reduced links: P and the projected K and C
  std::unique_ptr<Projection> projection_;
  std::unique_ptr<ReducedFactor> reduced_;
  bool damped_, keep_stiffness_;
  double h_ = 0.0;
};

}  // namespace rfem
