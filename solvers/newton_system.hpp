#pragma once
// The Newton system of IDA for y = [q_u; v_u]:
//   [c I, −I; K, C + c M] [x1; x2] = [b1; b2]
// solved through its Schur complement (c² M + c C + K) x2 = c b2 − K b1, x1 = (b1 + x2)/c, with
// S = c² M + c C + K factorised by CHOLMOD on the bordered pattern (FORMULATION.md §5). M, C, K are
// the mass, sde damping and sde stiffness (the symmetric parts of the exact Jacobian), so the solve
// is exact for that approximate Jacobian.
#include "assembly/assemble.hpp"
#include "solvers/cholmod_solver.hpp"

namespace rfem {

class NewtonSystem {
 public:
  /// base_col[j]: joint j's column among the unknowns (numbered after the 6n rfe coordinates), −1
  /// if prescribed; nb = number of unknown joints.
  NewtonSystem(const Model& model, std::vector<int> base_col, int nb);
  /// Assembles and factorises at (q, v) for coefficient c. Returns false if S is not positive definite.
  bool setup(const VecX& q, const VecX& v, double c);
  /// Solves for x = [x1; x2] (2·size()) given b (2·size()), with the c of the last setup.
  void solve(const double* b, double* x) const;
  int size() const { return pattern_.size(); }
  const BorderedPattern& pattern() const { return pattern_; }

 private:
  void stiffness_times(const double* x, double* y) const;
  const Model& model_;
  std::vector<int> base_col_;
  BorderedPattern pattern_;
  CholmodSolver solver_;
  std::vector<double> S_, K_;
  double c_ = 0.0;
};

}  // namespace rfem
