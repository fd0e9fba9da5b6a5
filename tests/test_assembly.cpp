// The sparse bordered assembly equals the dense reference built from the paper's definitions
// ([3.10]–[3.11], every body and coordinate), with 1 and 2 threads (FORMULATION.md §7 invariant 9);
// the CHOLMOD solve equals a dense solve. Both sides are computed in double precision from the
// same kernels' inputs, so they agree to round-off (1e-12 relative).
#include <gtest/gtest.h>
#include <omp.h>

#include "assembly/assemble.hpp"
#include "assembly/dense_reference.hpp"
#include "solvers/cholmod_solver.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {
std::vector<double> newton_values(const Model& m, const BorderedPattern& p, const VecX& q, const VecX& v, int threads) {
  omp_set_num_threads(threads);
  std::vector<int> cols(m.m());
  for (int j = 0; j < m.m(); ++j) cols[j] = 6 * m.n() + j;
  MatrixTerms t;
  t.mass = 400.0;
  t.damping = 20.0;
  t.stiffness = 1.0;
  t.gravity = true;
  std::vector<double> vals;
  assemble_matrix(m, p, cols, q, v, t, vals);
  return vals;
}
}  // namespace

TEST(Assembly, SparseEqualsDenseReferenceWithOneAndTwoThreads) {
  set_parallel_min_rfes(1);  // exercise the parallel paths on a small model
  const Model m = test::spatial_arm(7, 0.002);
  VecX q, v, a;
  test::random_state(m, 11, q, v, a);
  const BorderedPattern p(m.n(), m.m());
  const MatX ref = 400.0 * dense_mass_matrix(m, q) + 20.0 * dense_damping(m, q) + dense_stiffness(m, q, true);
  for (int threads : {1, 2}) {
    const MatX S = to_dense(p, newton_values(m, p, q, v, threads));
    EXPECT_LT((S - ref).norm() / ref.norm(), 1e-12) << threads << " thread(s)";
  }
  const auto v1 = newton_values(m, p, q, v, 1), v2 = newton_values(m, p, q, v, 2);
  EXPECT_EQ(v1, v2) << "assembly must not depend on the thread count";
}

TEST(Assembly, ForcesIndependentOfThreadCount) {
  const Model m = test::spatial_arm(300, 0.001);
  VecX q, v, a;
  test::random_state(m, 12, q, v, a);
  VecX f1, f2;
  omp_set_num_threads(1);
  generalised_forces(m, q, v, a, ForceTerms{}, f1);
  omp_set_num_threads(2);
  generalised_forces(m, q, v, a, ForceTerms{}, f2);
  EXPECT_EQ((f1 - f2).lpNorm<Eigen::Infinity>(), 0.0);
}

TEST(Assembly, CholmodSolveEqualsDenseSolve) {
  const Model m = test::spatial_arm(9, 0.002);
  VecX q, v, a;
  test::random_state(m, 13, q, v, a);
  const BorderedPattern p(m.n(), m.m());
  const auto vals = newton_values(m, p, q, v, 2);
  CholmodSolver solver(p);
  ASSERT_TRUE(solver.factorize(vals));
  VecX x = a;
  solver.solve(x);
  const VecX ref = to_dense(p, vals).ldlt().solve(a);
  EXPECT_LT((x - ref).norm() / ref.norm(), 1e-10);
}

TEST(Assembly, PatternHasNoFill) {
  // The number of stored entries per rfe is fixed (21 own + 36 coupling + 6 per base column),
  // so storage and factorisation are O(n).
  const BorderedPattern a(100, 3), b(200, 3);
  EXPECT_EQ(b.nnz() - a.nnz(), 100 * (21 + 36 + 18));
}
