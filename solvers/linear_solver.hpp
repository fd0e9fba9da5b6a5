#pragma once
// A symmetric positive definite solver on the bordered pattern, in phases: construct (analyse the
// pattern once), factorize (new values, same pattern), solve. A solver shares its pattern (the
// pattern lives as long as any solver or system that uses it); solvers are neither copied nor moved
// (they live behind a pointer).
#include <memory>
#include <string>
#include <vector>

#include "../assembly/pattern.hpp"
#include "../core/types.hpp"

namespace rfem {

class LinearSolver {
 public:
  LinearSolver() = default;
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;
  virtual ~LinearSolver() = default;
  /// Refactorises with new values (pattern order). False if not positive definite. The solver
  /// may keep and overwrite `values` (the chain solver factorises in place): they belong to it
  /// until the next factorisation.
  virtual bool factorize(std::vector<double>& values) = 0;
  /// Solves S x = b in place with the last successful factorisation.
  virtual void solve(VecX& b) const = 0;
  /// Threads the solver may use (results do not depend on it).
  virtual void set_threads(int) {}
};

/// "chain": the block Cholesky of the bordered chain, two sweeps on two threads
/// (solvers/chain_solver.hpp); "cholmod": SuiteSparse CHOLMOD's simplicial LDLᵀ (one thread).
enum class LinearSolverKind { Chain, Cholmod };
std::string linear_solver_name(LinearSolverKind k);
bool parse_linear_solver(const std::string& name, LinearSolverKind& k);
std::unique_ptr<LinearSolver> make_linear_solver(LinearSolverKind k, std::shared_ptr<const BorderedPattern> pattern);

}  // namespace rfem
