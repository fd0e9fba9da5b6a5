// The block Cholesky of the bordered chain (solvers/chain_solver.hpp) against a dense solve, for
// every shape the split can take (no rfes, one, two, odd and even chains, with and without a
// border, several chains each with its own border columns), and bit-identical results with the
// sweeps on one and on two threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>

#include "../assembly/assemble.hpp"
#include "../solvers/chain_solver.hpp"
#include "../solvers/cholmod_solver.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

// A random symmetric positive definite matrix on the pattern: diagonally dominant values.
std::vector<double> random_spd(const BorderedPattern& p, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> v(p.nnz());
  for (auto& x : v) x = u(gen);
  for (int c = 0; c < p.size(); ++c) v[p.slot(c, c)] = 40.0 + 10.0 * u(gen);
  return v;
}

}  // namespace

TEST(ChainSolver, EqualsDenseSolveForEveryShape) {
  for (int nb : {0, 1, 3})
    for (int n : {0, 1, 2, 3, 4, 7, 40}) {
      if (n == 0 && nb == 0) continue;
      const auto pp = std::make_shared<const BorderedPattern>(n, nb);
  const BorderedPattern& p = *pp;
      auto v = random_spd(p, 17 + 3 * n + nb);
      const MatX A = to_dense(p, v);
      ChainSolver cs(pp);
      ASSERT_TRUE(cs.factorize(v)) << "n = " << n << ", nb = " << nb;
      VecX b = VecX::LinSpaced(p.size(), -1.0, 2.0), x = b;
      cs.solve(x);
      const VecX ref = A.ldlt().solve(b);
      EXPECT_LT((x - ref).norm(), 1e-13 * ref.norm()) << "n = " << n << ", nb = " << nb;
    }
}

TEST(ChainSolver, MatchesCholmodOnANewtonMatrix) {
  // S = M + hC + h²K of a real link with two free joints at a deformed, moving state: the
  // conditioning the time integration sees (stiff axial springs against light rfes).
  const Model m = test::spatial_arm(30, 2e-3);
  VecX q, v, a;
  test::random_state(m, 7, q, v, a);
  q.head(m.flexible_dofs()) *= 1e-3;  // a physical deformation (the random 5 cm would buckle the axial springs)
  const auto pp = std::make_shared<const BorderedPattern>(m.n(), 2);
  const BorderedPattern& p = *pp;
  for (double h : {1e-4, 1e-2}) {
    MatrixTerms t;
    t.mass = 1.0;
    t.damping = h;
    t.stiffness = h * h;
    std::vector<double> values;
    assemble_matrix(m, p, {m.flexible_dofs(), m.joint_index(1)}, q, v, t, values);
    ChainSolver chain(pp);
    CholmodSolver cholmod(pp);
    ASSERT_TRUE(cholmod.factorize(values));
    ASSERT_TRUE(chain.factorize(values));  // in place: after CHOLMOD has copied them
    VecX x1 = VecX::LinSpaced(p.size(), 1.0, -1.0), x2 = x1;
    chain.solve(x1);
    cholmod.solve(x2);
    EXPECT_LT((x1 - x2).norm(), 1e-10 * x2.norm()) << "h = " << h;
  }
}

TEST(ChainSolver, RefusesAnIndefiniteMatrix) {
  const auto pp = std::make_shared<const BorderedPattern>(5, 2);
  const BorderedPattern& p = *pp;
  auto v = random_spd(p, 3);
  v[p.slot(6 * 4 + 2, 6 * 4 + 2)] = -50.0;  // a negative pivot in the bottom sweep
  ChainSolver cs(pp);
  EXPECT_FALSE(cs.factorize(v));
}

TEST(ChainSolver, OneAndTwoThreadsAreBitIdentical) {
  const auto pp = std::make_shared<const BorderedPattern>(101, 3);
  const BorderedPattern& p = *pp;
  const auto v0 = random_spd(p, 5);
  VecX x[2];
  std::vector<double> v[2] = {v0, v0};
  for (int t : {1, 2}) {
    ChainSolver cs(pp);
    cs.set_threads(t);
    ASSERT_TRUE(cs.factorize(v[t - 1]));
    x[t - 1] = VecX::LinSpaced(p.size(), 1.0, -3.0);
    cs.solve(x[t - 1]);
  }
  EXPECT_EQ((x[0] - x[1]).cwiseAbs().maxCoeff(), 0.0);
}

namespace {
// Chains of 4, 1 and 7 blocks over a border of 5, each with its own columns (one with none).
std::shared_ptr<const BorderedPattern> several_chains() {
  std::vector<BorderedPattern::Chain> chains(3);
  chains[0] = {0, 4, {0, 2}};
  chains[1] = {4, 1, {}};
  chains[2] = {5, 7, {1, 2, 3, 4}};
  return std::make_shared<const BorderedPattern>(chains, 5);
}
}  // namespace

TEST(ChainSolver, SeveralChainsWithTheirOwnBordersEqualDenseSolve) {
  const auto pp = several_chains();
  const BorderedPattern& p = *pp;
  EXPECT_EQ(p.slot(0, 6 * 12 + 1), -1) << "chain 0 is not coupled to border column 1";
  EXPECT_EQ(p.slot(6 * 3, 6 * 4), -1) << "chains are not coupled to each other";
  EXPECT_EQ(static_cast<long>(p.csc().rowind.size()), p.entries());
  const auto v0 = random_spd(p, 29);
  const MatX A = to_dense(p, v0);
  const VecX b = VecX::LinSpaced(p.size(), -1.0, 2.0), ref = A.ldlt().solve(b);
  VecX x[2];
  for (int t : {1, 2}) {
    std::vector<double> v = v0;
    ChainSolver cs(pp);
    cs.set_threads(t);
    ASSERT_TRUE(cs.factorize(v));
    x[t - 1] = b;
    cs.solve(x[t - 1]);
    EXPECT_LT((x[t - 1] - ref).norm(), 1e-13 * ref.norm()) << t << " thread(s)";
  }
  EXPECT_EQ((x[0] - x[1]).cwiseAbs().maxCoeff(), 0.0);
  std::vector<double> v = v0;
  CholmodSolver cholmod(pp);
  ASSERT_TRUE(cholmod.factorize(v));
  VecX y = b;
  cholmod.solve(y);
  EXPECT_LT((y - ref).norm(), 1e-12 * ref.norm());
}

TEST(ChainSolver, MatchesCholmodOnATreeNewtonMatrix) {
  // A tree of links and joints (test::tree_arm): four rfes carry joints or a link, so there are
  // five chains (A and B are cut in two, C is one), their borders hold different joints and
  // carrying rfes.
  const Model m = test::tree_arm(6, 2e-3);
  VecX q, v, a;
  test::random_state(m, 8, q, v, a);
  q.head(m.flexible_dofs()) *= 1e-3;
  std::vector<int> cols(m.m(), -1);
  cols[0] = m.flexible_dofs();
  cols[2] = m.flexible_dofs() + 1;  // shoulder and wrist free, elbow and slider prescribed
  const auto pp = std::make_shared<const BorderedPattern>(m, cols);
  const BorderedPattern& p = *pp;
  EXPECT_EQ(p.chains().size(), 5u);
  EXPECT_EQ(p.n_base(), 6 * m.carrying + 2);
  for (double h : {1e-4, 1e-2}) {
    MatrixTerms t;
    t.mass = 1.0;
    t.damping = h;
    t.stiffness = h * h;
    t.gravity = true;
    std::vector<double> values;
    assemble_matrix(m, p, cols, q, v, t, values);
    ChainSolver chain(pp);
    CholmodSolver cholmod(pp);
    ASSERT_TRUE(cholmod.factorize(values));
    ASSERT_TRUE(chain.factorize(values));
    VecX x1 = VecX::LinSpaced(p.size(), 1.0, -1.0), x2 = x1;
    chain.solve(x1);
    cholmod.solve(x2);
    EXPECT_LT((x1 - x2).norm(), 1e-10 * x2.norm()) << "h = " << h;
  }
}
