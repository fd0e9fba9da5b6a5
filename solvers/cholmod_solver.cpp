#include "cholmod_solver.hpp"

#include <cholmod.h>

#include <algorithm>
#include <stdexcept>

#include "../core/check.hpp"

namespace rfem {

CholmodSolver::CholmodSolver(std::shared_ptr<const BorderedPattern> pattern)
    : shared_(pattern ? std::move(pattern) : throw std::invalid_argument("CholmodSolver: no pattern")), pattern_(*shared_) {
  common_ = new cholmod_common;
  cholmod_l_start(common_);
  common_->supernodal = CHOLMOD_SIMPLICIAL;
  common_->final_ll = 0;  // LDLᵀ
  common_->nmethods = 1;
  common_->method[0].ordering = CHOLMOD_NATURAL;
  common_->postorder = 0;
  common_->print = 0;
  common_->quick_return_if_not_posdef = 1;
  // A views the pattern's compressed columns and, at each factorisation, the values gathered into them.
  static_assert(sizeof(SuiteSparse_long) == sizeof(long));
  A_ = new cholmod_sparse{};
  A_->nrow = A_->ncol = static_cast<size_t>(pattern_.size());
  const auto& z = pattern_.csc();
  A_->nzmax = z.rowind.size();
  A_->p = const_cast<long*>(z.colptr.data());
  A_->i = const_cast<long*>(z.rowind.data());
  A_->stype = 1;  // upper triangle stored
  A_->itype = CHOLMOD_LONG;
  A_->xtype = CHOLMOD_PATTERN;  // the analysis needs no values
  A_->dtype = CHOLMOD_DOUBLE;
  A_->sorted = 1;
  A_->packed = 1;
  L_ = cholmod_l_analyze(A_, common_);
  A_->xtype = CHOLMOD_REAL;
  if (!L_) throw std::runtime_error("CHOLMOD analysis failed");
}

CholmodSolver::~CholmodSolver() {
  if (L_) cholmod_l_free_factor(&L_, common_);
  delete A_;  // its arrays belong to the pattern and the caller
  cholmod_l_finish(common_);
  delete common_;
}

bool CholmodSolver::factorize(std::vector<double>& values) {
  RFEM_CHECK_ARGUMENT_SIZE(values.size(), pattern_.nnz(), "values");
  const auto& z = pattern_.csc();
  x_.resize(z.slot.size());
  for (size_t p = 0; p < x_.size(); ++p) x_[p] = values[z.slot[p]];
  A_->x = x_.data();
  cholmod_l_factorize(A_, L_, common_);
  A_->x = nullptr;
  if (common_->status == CHOLMOD_NOT_POSDEF) {
    failed_column_ = static_cast<long>(L_->minor);
    return false;
  }
  if (common_->status < CHOLMOD_OK) throw std::runtime_error("CHOLMOD factorisation failed");
  failed_column_ = -1;
  return true;
}

void CholmodSolver::solve(VecX& b) const {
  RFEM_CHECK_ARGUMENT_SIZE(b.size(), pattern_.size(), "b");
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
