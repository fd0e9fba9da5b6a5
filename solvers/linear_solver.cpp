#include "linear_solver.hpp"

#include "chain_solver.hpp"
#include "cholmod_solver.hpp"

namespace rfem {

std::string linear_solver_name(LinearSolverKind k) { return k == LinearSolverKind::Cholmod ? "cholmod" : "chain"; }

bool parse_linear_solver(const std::string& name, LinearSolverKind& k) {
  if (name == "chain") k = LinearSolverKind::Chain;
  else if (name == "cholmod") k = LinearSolverKind::Cholmod;
  else return false;
  return true;
}

std::unique_ptr<LinearSolver> make_linear_solver(LinearSolverKind k, std::shared_ptr<const BorderedPattern> pattern) {
  if (k == LinearSolverKind::Cholmod) return std::make_unique<CholmodSolver>(std::move(pattern));
  return std::make_unique<ChainSolver>(std::move(pattern));
}

}  // namespace rfem
