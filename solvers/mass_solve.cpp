#include "mass_solve.hpp"
#include "../core/check.hpp"

namespace rfem {

bool solve_mass(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                const VecX& q, const VecX& v, VecX& b, std::vector<double>& values, Workspace* ws) {
  RFEM_CHECK_ARGUMENT_SIZE(q.size(), model.dof(), "q");
  RFEM_CHECK_ARGUMENT_SIZE(v.size(), model.dof(), "v");
  RFEM_CHECK_ARGUMENT_SIZE(base_col.size(), model.m(), "base_col");
  RFEM_CHECK_ARGUMENT_SIZE(b.size(), pattern.size(), "b");
  MatrixTerms mt;
  mt.mass = 1.0;
  assemble_matrices(model, pattern, base_col, q, v, mt, values, {}, nullptr, ws);
  const int n = pattern.n_blocks(), nb = pattern.n_base(), n6 = 6 * n;
  auto entry = [&](int r, int c) { return values[pattern.slot(std::min(r, c), std::max(r, c))]; };
  MatX S(nb, nb);  // Schur complement on the border
  for (int i = 0; i < nb; ++i)
    for (int j = 0; j < nb; ++j) S(i, j) = entry(n6 + i, n6 + j);
  VecX rb = b.tail(nb);
  // Each rfe's 6×6 block is factorised twice (here and for the back-substitution) rather than
  // kept: n factors would be 0.3 kB per rfe at the start of a run, above the integration's peak.
  auto block_factor = [&](int k) {
    Mat6 Mkk;
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) Mkk(i, j) = entry(6 * k + i, 6 * k + j);
    return Eigen::LLT<Mat6>(Mkk);
  };
  for (int k = 0; k < n; ++k) {
    const std::vector<int>& cols = pattern.chains()[pattern.chain_of(k)].cols;
    const int w = static_cast<int>(cols.size());
    Eigen::Matrix<double, 6, Eigen::Dynamic> B(6, w);
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < w; ++j) B(i, j) = entry(6 * k + i, n6 + cols[j]);
    const Eigen::LLT<Mat6> llt = block_factor(k);
    if (llt.info() != Eigen::Success) return false;
    if (w > 0) {
      const MatX s = B.transpose() * llt.solve(B);
      const VecX r = B.transpose() * llt.solve(b.segment<6>(6 * k));
      for (int i = 0; i < w; ++i) {
        rb[cols[i]] -= r[i];
        for (int j = 0; j < w; ++j) S(cols[i], cols[j]) -= s(i, j);
      }
    }
  }
  if (nb > 0) {
    Eigen::LLT<MatX> sl(S);
    if (sl.info() != Eigen::Success) return false;
    b.tail(nb) = sl.solve(rb);
  }
  for (int k = 0; k < n; ++k) {
    const std::vector<int>& cols = pattern.chains()[pattern.chain_of(k)].cols;
    Vec6 rhs = b.segment<6>(6 * k);
    for (int col : cols)
      for (int i = 0; i < 6; ++i) rhs[i] -= entry(6 * k + i, n6 + col) * b[n6 + col];
    b.segment<6>(6 * k) = block_factor(k).solve(rhs);
  }
  return true;
}

}  // namespace rfem
