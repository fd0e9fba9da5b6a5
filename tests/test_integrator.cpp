// The time integrators themselves: the ESDIRK methods reach their design order on a smooth problem
// (soft links: every mode resolved by the steps); the default tolerances keep the integration
// error of the paper's case below the 1e-4 target; the thread governor picks the faster
// team and keeps checking.
#include <gtest/gtest.h>

#include <cmath>

#include "../assembly/workspace.hpp"
#include "../simulation/inputs.hpp"
#include "../solvers/integrator.hpp"
#include "../solvers/thread_governor.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

JointInput free_joint(double q0, double v0, double tau) {
  JointInput j;
  j.torque = constant_torque(tau);
  j.q0 = q0;
  j.v0 = v0;
  return j;
}

std::vector<VecX> trajectory(const Model& m, const std::vector<JointInput>& in, IntegratorOptions o) {
  std::vector<VecX> q;
  const RunOutcome r = integrate(m, in, o, [&](const OutputSample& x) { q.push_back(x.q); });
  EXPECT_TRUE(r.completed()) << r.status;
  return q;
}

double max_difference(const std::vector<VecX>& a, const std::vector<VecX>& b) {
  double e = 0.0;
  for (size_t i = 0; i < a.size(); ++i) e = std::max(e, (a[i] - b[i]).lpNorm<Eigen::Infinity>());
  return e;
}

}  // namespace

TEST(Integrator, EsdirkReachesItsDesignOrder) {
  // Links 100 times softer than aluminium, 3 rfes: the fastest mode (ω ≈ 500 rad/s) is resolved
  // by the steps below (hω ≤ 0.3), so the error is the method's classical one, C hᵖ. Two free joints under
  // constant torques, damping: every term of the equations but gravity is exercised.
  Model m = test::spatial_arm(3, 1e-4, 1e-2);
  m.gravity = 0.0;
  const std::vector<JointInput> in{free_joint(0.2, 0.5, 0.5), free_joint(-0.3, 0.2, -0.2)};
  struct Method {
    const char* table;
    int order;
  };
  for (const Method& method : {Method{"ESDIRK547L2SA2_7_4_5", 5}, Method{"ESDIRK43I6L2SA_6_3_4", 4},
                               Method{"ESDIRK324L2SA_4_2_3", 3}}) {
    IntegratorOptions o;
    o.esdirk_table = method.table;
    o.t_end = 0.1;
    o.output_dt = 0.01;
    o.rtol = 1e-11;  // with fixed steps only the Newton iteration sees these: far below the errors
    o.atol = 1e-14;
    o.atol_velocity = 1e-12;
    o.fixed_step = 1.0 / 51200;
    const auto ref = trajectory(m, in, o);
    std::vector<double> err;
    for (int steps : {1600, 3200, 6400}) {
      o.fixed_step = 1.0 / steps;
      err.push_back(max_difference(trajectory(m, in, o), ref));
    }
    for (size_t i = 1; i < err.size(); ++i) {
      const double p = std::log2(err[i - 1] / err[i]);
      RecordProperty(std::string(method.table) + "_order_" + std::to_string(i), std::to_string(p));
      // Asymptotic constants differ between step pairs; ±0.5 still tells 3, 4 and 5 apart.
      EXPECT_NEAR(p, method.order, 0.5) << method.table << ": errors " << err[i - 1] << " → " << err[i];
    }
  }
}

TEST(Integrator, BdfFailureKeepsIdasOwnMessage) {
  // Too few steps allowed: IDA stops with IDA_TOO_MUCH_WORK, and its own sentence (which names
  // mxstep and the time) reaches the run's status instead of a bare flag.
  Model m = test::spatial_arm(3, 1e-4, 1e-2);
  const std::vector<JointInput> in{free_joint(0.2, 0.5, 0.5), free_joint(-0.3, 0.2, -0.2)};
  IntegratorOptions o;
  o.kind = IntegratorKind::Bdf;
  o.t_end = 0.1;
  o.output_dt = 0.1;
  o.max_steps = 3;
  const RunOutcome r = integrate(m, in, o, [](const OutputSample&) {});
  ASSERT_EQ(r.status.kind, RunStatus::Kind::Failed) << r.status;
  EXPECT_NE(r.status.reason.find("IDA_TOO_MUCH_WORK"), std::string::npos) << r.status;
  EXPECT_NE(r.status.reason.find("mxstep"), std::string::npos) << r.status;
}

TEST(Integrator, DefaultTolerancesMeetTheAccuracyTarget) {
  // The paper's deployment at n = 6, first 5 s: at the default settings the tip deflections, the
  // torsion and the joint-3 torque (kinematic input) and the tip series (force input) are within
  // 1e-4 of their peaks of a run at rtol 1e-10 (the accuracy the defaults promise; that run's own error is ~1e-6).
  const Case c = read_case(test::source_path("cases/paper_deployment.toml"), {"simulation.t_end=5"});
  const Model flex = build_model(c, 6), rigid = rigidify(flex);
  const auto laws = joint_inputs(c);
  const auto forces = rigid_torque_inputs(std::make_shared<const Model>(rigid), laws);
  for (const auto* inputs : {&laws, &forces}) {
    std::vector<OutputSample> run[2];
    for (int tight : {0, 1}) {
      IntegratorOptions o = c.sim.options;
      if (tight) {
        o.rtol = 1e-10;
        o.atol = 1e-13;
        o.atol_velocity = 1e-7;
        o.max_steps = 10000000;
      }
      integrate(flex, *inputs, o, [&](const OutputSample& x) { run[tight].push_back(x); });
    }
    ASSERT_EQ(run[0].size(), run[1].size());
    const bool kinematic = inputs == &laws;
    double err[4] = {0, 0, 0, 0}, peak[4] = {0, 0, 0, 0};
    for (size_t i = 0; i < run[0].size(); ++i) {
      const Vec6 a = tip_motion(flex, 0, run[0][i].q), b = tip_motion(flex, 0, run[1][i].q);
      const double xa[4] = {a[1], a[2], a[3], run[0][i].tau[2]}, xb[4] = {b[1], b[2], b[3], run[1][i].tau[2]};
      for (int k = 0; k < 4; ++k) {
        err[k] = std::max(err[k], std::abs(xa[k] - xb[k]));
        peak[k] = std::max(peak[k], std::abs(xb[k]));
      }
    }
    const char* names[4] = {"u1", "u2", "theta", "tau3"};
    for (int k = 0; k < (kinematic ? 4 : 3); ++k) {
      RecordProperty(std::string(kinematic ? "kinematic_" : "force_") + names[k], std::to_string(err[k] / peak[k]));
      EXPECT_LT(err[k], 1e-4 * peak[k]) << (kinematic ? "kinematic " : "force ") << names[k];
    }
  }
}

TEST(ThreadGovernor, PicksTheFasterTeamAndKeepsChecking) {
  // Two threads twice as fast: chosen after the first probes. Then the machine gets busy (two
  // threads three times slower than one): the next probe switches to one thread.
  ThreadGovernor g(2, false);
  auto cost = [](int team, bool busy) { return team > 1 ? (busy ? 3e-3 : 0.5e-3) : 1e-3; };
  for (int i = 0; i < 40; ++i) g.record(cost(g.threads(), false));
  EXPECT_EQ(g.threads(), 2);
  const long before = g.evaluations(1);
  for (int i = 0; i < 2000 && g.threads() != 1; ++i) g.record(cost(g.threads(), true));
  EXPECT_EQ(g.threads(), 1) << "a busy machine must make one thread the choice";
  for (int i = 0; i < 3000; ++i) g.record(cost(g.threads(), true));
  EXPECT_GT(g.evaluations(1), before + 2000) << "and one thread stays the choice while it is faster";
  EXPECT_GT(g.evaluations(2), 100) << "while two threads are still tried now and then";
  // Fixed by the user: the team is kept on an idle machine — even where one thread would
  // be 10 % faster (timing noise, a small n) — and falls back to one thread only under foreign load
  // (the team 3× slower at every barrier), coming back once the machine is idle again.
  ThreadGovernor fixed(2, true);
  long probes = 0;
  for (int i = 0; i < 20000; ++i) {
    fixed.record(cost(fixed.threads(), false));
    probes += fixed.threads() == 1;
  }
  EXPECT_EQ(fixed.threads(), 2);
  EXPECT_LT(probes, 0.01 * 20000) << "the safety net's probes of one thread cost little";
  ThreadGovernor close(2, true);  // one thread 10 % faster than the team: still the team
  long team_evals = 0;
  for (int i = 0; i < 20000; ++i) {
    team_evals += close.threads() == 2;
    close.record(close.threads() > 1 ? 1.1e-3 : 1e-3);
  }
  EXPECT_GT(team_evals, 0.98 * 20000);
  for (int i = 0; i < 4000 && fixed.threads() != 1; ++i) fixed.record(cost(fixed.threads(), true));
  EXPECT_EQ(fixed.threads(), 1) << "a fixed team under foreign load must fall back to one thread";
  for (int i = 0; i < 40000 && fixed.threads() != 2; ++i) fixed.record(cost(fixed.threads(), false));
  EXPECT_EQ(fixed.threads(), 2) << "and come back to the team once the machine is idle";
  // A team far slower than one thread (a time slice lost at every barrier) is given up after its
  // first two timed evaluations, not thirteen.
  ThreadGovernor heavy(2, true);
  for (int i = 0; i < 200; ++i) heavy.record(heavy.threads() > 1 ? 30e-3 : 1e-3);
  EXPECT_EQ(heavy.threads(), 1);
  EXPECT_LE(heavy.evaluations(2), 3);
  ThreadGovernor one(1, true);
  for (int i = 0; i < 100; ++i) one.record(1e-3);
  EXPECT_EQ(one.threads(), 1);
}

TEST(ThreadGovernor, MoreThreadsThanCoresAreNamed) {
  const int cores = available_cores();
  ASSERT_GE(cores, 1);
  EXPECT_EQ(oversubscription(1, cores, "--threads"), "");
  EXPECT_EQ(oversubscription(cores, 1, "--jobs"), "");
  const std::string w = oversubscription(cores, 2, "--jobs");
  EXPECT_NE(w.find(std::to_string(2 * cores) + " threads on " + std::to_string(cores) + " core"), std::string::npos) << w;
}
