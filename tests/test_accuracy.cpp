// Asking for an accuracy (studies/refine.hpp: RefineRequest::accuracy): n doubles until every
// quantity's error bar (solvers/refinement.hpp, Roache's GCI plus the integration check) meets the
// relative target. The bar must contain the exact value and the value must then be as accurate as
// asked — against exact beam results (the Timoshenko cantilever's frequencies) and a reference run
// of Kane's spin-up; a target no n up to the limit meets is reported short, by how much, not met.
#include <gtest/gtest.h>

#include <cmath>

#include "../solvers/beam_theory.hpp"
#include "../studies/refine.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

TEST(Accuracy, CantileverFrequenciesMeetEveryTargetAndTheirBarsHoldTheExactValue) {
  const Case c = read_case(test::source_path("cases/kane_beam.toml"), {"sections.kane.Iz=3e-7"});
  const Segment& seg = c.links[0].link.segments[0];
  int last_n = 0;
  for (double target : {1e-2, 1e-3, 1e-4, 1e-5}) {
    RefineRequest rq;
    rq.quantities = {"bending-y:1", "bending-y:2", "bending-y:3"};
    rq.accuracy = target;
    const RefineResult res = refine(c, rq);
    ASSERT_TRUE(res.met) << "target " << target << ": " << (res.shortfall.empty() ? "" : res.shortfall[0]);
    EXPECT_GE(res.ns.back(), last_n);  // (a tighter target never needs fewer rfes)
    last_n = res.ns.back();
    for (int k = 1; k <= 3; ++k) {
      const Refinement& t = res.tables[k - 1];
      const double exact = beam::cantilever_omega_timoshenko(seg, ModeKind::BendingY, k) / (2 * M_PI);
      const double value = t.rows.back().value, truth = std::abs(value - exact);
      EXPECT_LE(truth, t.error) << "mode " << k << ", target " << target << ": the bar misses the exact value";
      EXPECT_LE(truth, target * exact) << "mode " << k << ", target " << target << ": not as accurate as asked";
    }
  }
  EXPECT_LE(last_n, 512);  // (1e-5 on the third mode: n ≈ 310 by the 1/n² law, the doubling from 8 gives 512)
}

// Kane's spin-up (Ω = 6 rad/s, T = 15 s): the tip's peak u1 with a target of 1e-3. Reference: the
// same quantity at n = 320 with rtol 1e-9, atol 1e-12, 0.5738494557 m (`rfem refine
// cases/kane_spinup.toml --quantity peak:u1 --n 160,320 --set simulation.rtol=1e-9 --set
// simulation.atol=1e-12`; its own discretisation error ≈ 1.3e-5/3 = 4.4e-6 m, well inside the bar).
TEST(Accuracy, KaneSpinUpTipPeakMeetsItsTargetWithTheReferenceInTheBar) {
  const Case c = read_case(test::source_path("cases/kane_spinup.toml"));
  RefineRequest rq;
  rq.quantities = {"peak:u1"};
  rq.accuracy = 1e-3;
  rq.threads = 1;
  const RefineResult res = refine(c, rq);
  ASSERT_TRUE(res.met) << (res.shortfall.empty() ? "" : res.shortfall[0]);
  const Refinement& t = res.tables[0];
  const double reference = 0.5738494557, value = t.rows.back().value;
  EXPECT_LE(std::abs(value - reference), t.error) << "n = " << res.ns.back() << ": the bar misses the reference";
  EXPECT_LE(res.ns.back(), 160);
  EXPECT_TRUE(std::isfinite(t.error_time));  // (the integration check ran: the time part is in the bar)
  EXPECT_LT(t.error_time, 0.01 * t.error);
}

TEST(Accuracy, ATargetNoNUpToTheLimitMeetsIsReportedShortByHowMuch) {
  const Case c = read_case(test::source_path("cases/kane_beam.toml"));
  RefineRequest rq;
  rq.quantities = {"mode:1"};
  rq.accuracy = 1e-9;
  rq.max_n = 64;
  const RefineResult res = refine(c, rq);
  EXPECT_FALSE(res.met);
  EXPECT_EQ(res.ns, (std::vector<int>{8, 16, 32, 64}));
  ASSERT_EQ(res.shortfall.size(), 1u);
  EXPECT_NE(res.shortfall[0].find("n ≈"), std::string::npos) << res.shortfall[0];
  // A target of 0, NaN or ≥ 1, and a target over a series of modes: one line, before any work.
  for (double bad : {0.0, double(NAN), 1.0, -1e-3}) {
    rq.accuracy = bad;
    EXPECT_THROW(refine(c, rq), CaseError) << bad;
  }
  rq.accuracy = 1e-3;
  rq.ns = {8};
  rq.modes = {2, 4};
  EXPECT_THROW(refine(c, rq), CaseError);
}
