#include "solvers/cholmod_solver.hpp"

#include <cholmod.h>

#include <algorithm>
#include <stdexcept>

namespace rfem {

CholmodSolver::CholmodSolver(const BorderedPattern& pattern) : pattern_(pattern) {
  common_ = new cholmod_common;
  cholmod_l_start(common_);
  common_->supernodal = CHOLMOD_SIMPLICIAL;
  common_->final_ll = 0;  // LDLᵀ
  common_->nmethods = 1;
  common_->method[0].ordering = CHOLMOD_NATURAL;
  common_->postorder = 0;
  common_->print = 0;
  common_->quick_return_if_not_posdef = 1;
  const long N = pattern.size();
  A_ = cholmod_l_allocate_sparse(N, N, pattern.nnz(), /*sorted*/ 1, /*packed*/ 1, /*stype upper*/ 1,
                                 CHOLMOD_REAL, common_);
  if (!A_) throw std::runtime_error("CHOLMOD could not allocate the matrix");
  std::copy(pattern.colptr().begin(), pattern.colptr().end(), static_cast<SuiteSparse_long*>(A_->p));
  std::copy(pattern.rowind().begin(), pattern.rowind().end(), static_cast<SuiteSparse_long*>(A_->i));
  std::fill_n(static_cast<double*>(A_->x), pattern.nnz(), 0.0);
  L_ = cholmod_l_analyze(A_, common_);
  if (!L_) throw std::runtime_error("CHOLMOD analysis failed");
}

CholmodSolver::~CholmodSolver() {
  if (L_) cholmod_l_free_factor(&L_, common_);
  if (A_) cholmod_l_free_sparse(&A_, common_);
  cholmod_l_finish(common_);
  delete common_;
}

bool CholmodSolver::factorize(const std::vector<double>& values) {
  std::copy(values.begin(), values.end(), static_cast<double*>(A_->x));
  cholmod_l_factorize(A_, L_, common_);
  if (common_->status == CHOLMOD_NOT_POSDEF) {
    failed_column_ = static_cast<long>(L_->minor);
    return false;
  }
  if (common_->status < CHOLMOD_OK) throw std::runtime_error("CHOLMOD factorisation failed");
  failed_column_ = -1;
  return true;
}

void CholmodSolver::solve(VecX& b) const {
  const long N = pattern_.size();
  cholmod_dense B;
  B.nrow = N;
  B.ncol = 1;
  B.nzmax = N;
  B.d = N;
  B.x = b.data();
  B.z = nullptr;
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  cholmod_dense* X = cholmod_l_solve(CHOLMOD_A, L_, &B, common_);
  if (!X) throw std::runtime_error("CHOLMOD solve failed");
  std::copy_n(static_cast<double*>(X->x), N, b.data());
  cholmod_l_free_dense(&X, common_);
}

}  // namespace rfem
