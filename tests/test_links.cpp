// Several flexible links (issue 10 §1–3, §8): a link mounted on another's tip through a locked
// joint is the same beam as one link of the combined length; a tree's modes and static deflection
// converge at second order in n.
#include <gtest/gtest.h>

#include <iomanip>
#include <limits>
#include <sstream>

#include "solvers/modes.hpp"
#include "solvers/statics.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {
std::string fmt(double x) {
  std::ostringstream os;
  os << std::setprecision(3) << x;
  return os.str();
}
}  // namespace

TEST(Links, TwoLinksInLineWithTheJointLockedAreOneLink) {
  // Kane's cantilever cut at 3.7 m into two links joined by a held revolute joint: link 2's rfe_0
  // and link 1's last rfe form, with the joint, the rigid body that straddles the cut in the
  // one-link discretisation, and link 2's coordinates are measured in a frame that turns with link
  // 1's tip. At the undeformed state the two coordinate sets are related by a linear map to first
  // order (the second-order terms of the map meet zero sde forces), so M and K are congruent and
  // the frequencies agree to round-off. Statically, under a tip load P the two descriptions differ
  // only through the geometric nonlinearity, at relative order (tip deflection / L).
  for (const auto& parts : {std::pair{4, 7}, std::pair{9, 15}}) {
    const Model one = test::beam_in_two(3.7, parts.first, parts.second, true);
    const Model two = test::beam_in_two(3.7, parts.first, parts.second, false);
    ASSERT_EQ(two.links.size(), 2u);
    ASSERT_EQ(two.carrying, 1);
    ASSERT_EQ(one.n(), two.n());
    const VecX none(0), held = VecX::Zero(1);
    const int all = one.flexible_dofs();
    const ModesResult a = compute_modes(one, none, none, all), b = compute_modes(two, held, held, all);
    // Every mode, to the round-off of a dense eigen-solution: ε λ_max / λ_i relative in λ_i (the
    // stiff axial sdes set λ_max), with a factor 1000 for the solver's constants and the reduction
    // by M's Cholesky factor (rfe masses and rotary inertias differ by 1e4), and at least 1e-11:
    // the two models' entries are built along different kinematic paths. A wrong mass or
    // stiffness anywhere shifts frequencies by far more (1e-3 and up). (The kinds of the
    // degenerate y/z pairs of this round beam may swap.)
    const double lmax = a.omega[all - 1] * a.omega[all - 1];
    double worst = 0.0;
    for (int i = 0; i < all; ++i) {
      const double tol = 1000 * std::numeric_limits<double>::epsilon() * lmax / (a.omega[i] * a.omega[i]) + 1e-11;
      EXPECT_NEAR(b.omega[i], a.omega[i], tol * a.omega[i]) << "mode " << i + 1 << ", parts " << parts.first << "+" << parts.second;
      worst = std::max(worst, std::abs(b.omega[i] / a.omega[i] - 1.0) / tol);
    }
    RecordProperty("frequency_difference_over_roundoff_" + std::to_string(parts.first + parts.second), fmt(worst));
    TipLoads P;
    P.force = Vec3(0.0, 0.0, -1e-3);  // [N]: a tip deflection of ~1.6e-5 m on 10 m
    const Vec6 ua = tip_motion(one, 0, solve_static(one, none, none, P).q);
    const Vec3 pa = tip_position(one, 0, solve_static(one, none, none, P).q);
    const Vec3 pb = tip_position(two, 1, solve_static(two, held, held, P).q);
    ASSERT_GT(std::abs(ua[2]), 1e-5);
    EXPECT_NEAR(pb.z(), pa.z(), 1e-5 * std::abs(ua[2])) << "tip deflection";
    RecordProperty("deflection_difference_" + std::to_string(parts.first + parts.second), fmt(std::abs(pb.z() / pa.z() - 1)));
  }
}
