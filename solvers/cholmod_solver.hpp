#pragma once
// CHOLMOD on the bordered pattern, in phases: analyse the pattern once (natural ordering: the
// pattern has no fill), refactorise numerically whenever values change, solve. Simplicial LDLᵀ
// (supernodes are tiny on this pattern: simplicial is 2–3× faster).
#include <memory>
#include <vector>

#include "linear_solver.hpp"

struct cholmod_common_struct;
struct cholmod_sparse_struct;
struct cholmod_factor_struct;

namespace rfem {

class CholmodSolver : public LinearSolver {
 public:
  /// Throws std::invalid_argument for a null pattern, std::runtime_error if CHOLMOD fails.
  explicit CholmodSolver(std::shared_ptr<const BorderedPattern> pattern);
  ~CholmodSolver() override;

  /// Refactorises with new values (pattern order). Returns false if the matrix is not positive
  /// definite (the caller may cut the step); the failing column is in failed_column().
  bool factorize(std::vector<double>& values) override;
  /// Solves S x = b in place with the last successful factorisation.
  void solve(VecX& b) const override;
  long failed_column() const { return failed_column_; }

 private:
  std::shared_ptr<const BorderedPattern> shared_;
  const BorderedPattern& pattern_;  // *shared_
  cholmod_common_struct* common_ = nullptr;
  cholmod_sparse_struct* A_ = nullptr;
  cholmod_factor_struct* L_ = nullptr;
  long failed_column_ = -1;
  std::vector<double> x_;  // the values in compressed columns
};

}  // namespace rfem
