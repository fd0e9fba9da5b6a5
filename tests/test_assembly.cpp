// The sparse bordered assembly equals the dense reference built from the paper's definitions
// ([3.10]–[3.11], every body and coordinate), with 1 and 2 threads (docs/formulation.md §7 invariant 9);
// the CHOLMOD solve equals a dense solve. Both sides are computed in double precision from the
// same kernels' inputs, so they agree to round-off (1e-12 relative).
#include <gtest/gtest.h>
#include <omp.h>

#include "../assembly/assemble.hpp"
#include "../assembly/dense_reference.hpp"
#include "../solvers/cholmod_solver.hpp"
#include "../solvers/mass_solve.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {
// Parallel paths on every chunk size that matters: chunks of 2 rfes put chunk boundaries between
// most sdes of a small model.
Workspace workspace(int threads, int chunk = 2) {
  Workspace ws;
  ws.parallel.threads = threads;
  ws.parallel.min_rfes = 1;
  ws.parallel.chunk = chunk;
  return ws;
}

// 400 M + 20 C + K with gravity, all joints unknown unless `cols` says otherwise.
std::vector<double> newton_values(const Model& m, const BorderedPattern& p, const VecX& q, const VecX& v, int threads,
                                  std::vector<int> cols = {}) {
  Workspace ws = workspace(threads);
  if (cols.empty())
    for (int j = 0; j < m.m(); ++j) cols.push_back(m.joint_index(j));
  MatrixTerms t;
  t.mass = 400.0;
  t.damping = 20.0;
  t.stiffness = 1.0;
  t.gravity = true;
  std::vector<double> vals;
  assemble_matrix(m, p, cols, q, v, t, vals, &ws);
  return vals;
}
}  // namespace

TEST(Assembly, SparseEqualsDenseReferenceWithOneAndTwoThreads) {
  Model m = test::spatial_arm(7, 0.002);
  m.joints[0].drive = {0.4, 0.8, 0.3, 0.5};  // rotor inertia, damping and friction on both joints
  m.joints[1].drive = {0.1, 0.0, 0.2, 0.05};
  VecX q, v, a;
  test::random_state(m, 11, q, v, a);
  const auto pp = std::make_shared<const BorderedPattern>(m.n(), m.m());
  const BorderedPattern& p = *pp;
  const MatX ref = 400.0 * dense_mass_matrix(m, q) + 20.0 * dense_damping(m, q, v) + dense_stiffness(m, q, true);
  for (int threads : {1, 2}) {
    const MatX S = to_dense(p, newton_values(m, p, q, v, threads));
    EXPECT_LT((S - ref).norm() / ref.norm(), 1e-12) << threads << " thread(s)";
  }
  const auto v1 = newton_values(m, p, q, v, 1), v2 = newton_values(m, p, q, v, 2);
  EXPECT_EQ(v1, v2) << "assembly must not depend on the thread count";
}

namespace {
// Forces, dissipation and energies: the same bits with 1 and 2 threads for a given chunk size,
// and the same values to round-off for any chunk size (the chunk boundaries lose nothing).
void expect_forces_independent_of_threads_and_chunks(const Model& m, unsigned seed) {
  VecX q, v, a;
  test::random_state(m, seed, q, v, a);
  q.head(m.flexible_dofs()) *= 0.1;
  VecX f[2], g;
  double pd[2], pg;
  Energies e[2];
  for (int t : {1, 2}) {
    Workspace ws = workspace(t, 7);
    generalised_forces(m, q, v, a, ForceTerms{}, f[t - 1], &pd[t - 1], &ws);
    e[t - 1] = energies(m, q, v, &ws);
  }
  EXPECT_EQ((f[0] - f[1]).lpNorm<Eigen::Infinity>(), 0.0);
  EXPECT_EQ(pd[0], pd[1]);
  EXPECT_EQ(e[0].kinetic, e[1].kinetic);
  EXPECT_EQ(e[0].elastic, e[1].elastic);
  EXPECT_EQ(e[0].dissipation_rate, e[1].dissipation_rate);
  Workspace serial = workspace(1, 100000);  // one chunk per link: no boundaries
  generalised_forces(m, q, v, a, ForceTerms{}, g, &pg, &serial);
  EXPECT_LT((f[0] - g).norm(), 1e-12 * g.norm());
  EXPECT_NEAR(pd[0], pg, 1e-12 * pg);
  EXPECT_NEAR(pg, e[0].dissipation_rate, 1e-12 * pg) << "dissipation of the force pass = that of energies()";
}
}  // namespace

TEST(Assembly, ForcesIndependentOfThreadCount) {
  expect_forces_independent_of_threads_and_chunks(test::spatial_arm(300, 0.001), 12);
}

TEST(Assembly, CholmodSolveEqualsDenseSolve) {
  const Model m = test::spatial_arm(9, 0.002);
  VecX q, v, a;
  test::random_state(m, 13, q, v, a);
  const auto pp = std::make_shared<const BorderedPattern>(m.n(), m.m());
  const BorderedPattern& p = *pp;
  auto vals = newton_values(m, p, q, v, 2);
  CholmodSolver solver(pp);
  ASSERT_TRUE(solver.factorize(vals));
  VecX x = a;
  solver.solve(x);
  const VecX ref = to_dense(p, vals).ldlt().solve(a);
  EXPECT_LT((x - ref).norm() / ref.norm(), 1e-10);
}

TEST(Assembly, PatternHasNoFill) {
  // The number of entries per rfe is fixed (21 own + 36 coupling + 6 per base column), so
  // storage and factorisation are O(n); the block storage holds 72 + 6 nb values per rfe.
  const BorderedPattern a(100, 3), b(200, 3);
  EXPECT_EQ(b.entries() - a.entries(), 100 * (21 + 36 + 18));
  EXPECT_EQ(b.nnz() - a.nnz(), 100 * (72 + 18));
  EXPECT_EQ(static_cast<long>(b.csc().rowind.size()), b.entries());
}

namespace {
// The rows and columns of a dense full-coordinate matrix that are unknowns: every rfe coordinate,
// then the joints with base_col ≥ 0 (EquationsOfMotion's numbering).
MatX unknown_part(const Model& m, const std::vector<int>& base_col, const MatX& A) {
  std::vector<int> idx;
  for (int i = 0; i < m.flexible_dofs(); ++i) idx.push_back(i);
  for (int j = 0; j < m.m(); ++j)
    if (base_col[j] >= 0) idx.push_back(m.joint_index(j));
  MatX out(idx.size(), idx.size());
  for (size_t r = 0; r < idx.size(); ++r)
    for (size_t c = 0; c < idx.size(); ++c) out(r, c) = A(idx[r], idx[c]);
  return out;
}
}  // namespace

TEST(Assembly, TreeSparseEqualsDenseReferenceWithOneAndTwoThreads) {
  // Links on links, joints on rfes, a branch and a slider (test::tree_arm), with every joint
  // unknown and with two of them prescribed (their rows and columns leave the pattern).
  Model m = test::tree_arm(3, 0.002);
  m.joints[1].drive = {0.3, 0.5, 0.2, 0.4};
  VecX q, v, a;
  test::random_state(m, 31, q, v, a);
  const MatX ref = 400.0 * dense_mass_matrix(m, q) + 20.0 * dense_damping(m, q, v) + dense_stiffness(m, q, true);
  for (const std::vector<int>& unknown : {std::vector<int>{0, 1, 2, 3}, std::vector<int>{1, 3}}) {
    std::vector<int> cols(m.m(), -1);
    for (size_t i = 0; i < unknown.size(); ++i) cols[unknown[i]] = m.flexible_dofs() + static_cast<int>(i);
    const auto pp = std::make_shared<const BorderedPattern>(m, cols);
  const BorderedPattern& p = *pp;
    const MatX expect = unknown_part(m, cols, ref);
    std::vector<double> vals[2];
    for (int threads : {1, 2}) {
      vals[threads - 1] = newton_values(m, p, q, v, threads, cols);
      EXPECT_LT((to_dense(p, vals[threads - 1]) - expect).norm() / expect.norm(), 1e-12) << threads << " thread(s)";
    }
    EXPECT_EQ(vals[0], vals[1]) << "assembly must not depend on the thread count";
  }
}

TEST(Assembly, TreeForcesIndependentOfThreadCountAndChunks) {
  expect_forces_independent_of_threads_and_chunks(test::tree_arm(40, 0.001), 32);
}

TEST(Assembly, TreeMassSolveEqualsDenseSolve) {
  // Accelerations by block elimination (solvers/mass_solve.hpp) on the tree's bordered pattern.
  const Model m = test::tree_arm(3);
  VecX q, v, a;
  test::random_state(m, 33, q, v, a);
  std::vector<int> cols(m.m(), -1);
  cols[1] = m.flexible_dofs();
  const auto pp = std::make_shared<const BorderedPattern>(m, cols);
  const BorderedPattern& p = *pp;
  const MatX M = unknown_part(m, cols, dense_mass_matrix(m, q));
  VecX b = VecX::LinSpaced(p.size(), -1.0, 1.0), x = b;
  std::vector<double> scratch;
  ASSERT_TRUE(solve_mass(m, p, cols, q, v, x, scratch));
  const VecX ref = M.ldlt().solve(b);
  EXPECT_LT((x - ref).norm(), 1e-10 * ref.norm());
}
