// Kane's spin-up beam and the paper's deployment: convergence in n, the role of the velocity-
// product terms, the rigid limit of very stiff links, and what the paper reports at n = 6.
#include <gtest/gtest.h>

#include <cmath>

#include "../simulation/inputs.hpp"
#include "../solvers/integrator.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

struct Sim {
  std::vector<OutputSample> s;
  RunOutcome outcome;
};

Sim simulate(const Model& m, const std::vector<JointInput>& in, double t_end, ForceTerms f = {}) {
  IntegratorOptions o;
  o.t_end = t_end;
  o.output_dt = 0.05;
  o.rtol = 1e-7;
  o.atol = 1e-9;
  o.forces = f;
  Sim r;
  r.outcome = integrate(m, in, o, [&](const OutputSample& x) { r.s.push_back(x); });
  return r;
}

JointInput law(std::shared_ptr<MotionLaw> m) {
  JointInput j;
  j.motion = std::move(m);
  j.q0 = j.motion->at(0.0).q;
  j.v0 = j.motion->at(0.0).qd;
  return j;
}

std::vector<JointInput> deployment() {
  const double alpha[3] = {0.5, 0.75, 1.0};
  std::vector<JointInput> in;
  for (int j = 0; j < 3; ++j) in.push_back(law(deployment_law(M_PI, alpha[j], 15.0)));
  return in;
}

double energy_balance_drift(const Sim& r) {
  const auto bal = [](const OutputSample& x) {
    return x.energy.kinetic + x.energy.elastic + x.energy.gravity + x.dissipated - x.input_work;
  };
  double d = 0.0;
  for (const auto& x : r.s) d = std::max(d, std::abs(bal(x) - bal(r.s.front())));
  return d;
}

}  // namespace

TEST(SpinUp, TipDeflectionConvergesAndNeedsVelocityProducts) {
  // Kane's beam spun up to Ω = 6 rad/s in T = 15 s: peak in-plane tip deflection (along y of the
  // rotating frame {r}) over 20 s for n = 5, 10, 20.
  const Case c = read_case(test::source_path("cases/kane_spinup.toml"));
  auto peak = [](const Model& m, const Sim& r) {
    double u = 0.0;
    for (const auto& x : r.s) u = std::max(u, std::abs(tip_motion(m, 0, x.q)[1]));
    return u;
  };
  // rtol = 1e-7: the balance closes to a few 1e-6 of the input work; 1e-5 leaves room.
  const double balance_tol = 1e-5;
  std::vector<double> u;
  for (int n : {5, 10, 20}) {
    const Model m = build_model(c, n);
    const Sim r = simulate(m, {law(spinup_law(0.0, 6.0, 15.0))}, 20.0);
    ASSERT_TRUE(r.outcome.completed()) << r.outcome.status;
    u.push_back(peak(m, r));
    // The balance closes: input work = kinetic + elastic energy (no damping, no gravity).
    EXPECT_LT(energy_balance_drift(r), balance_tol * r.s.back().input_work) << "n = " << n;
  }
  const double p = std::log2(std::abs((u[1] - u[0]) / (u[2] - u[1])));
  const double rich = u[2] + (u[2] - u[1]) / (std::pow(2.0, p) - 1.0);
  RecordProperty("observed_order", std::to_string(p));
  RecordProperty("peak_tip_deflection_extrapolated_m", std::to_string(rich));
  EXPECT_NEAR(p, 2.0, 0.3) << u[0] << " " << u[1] << " " << u[2];
  // The quasi-static lag under the peak angular acceleration 2Ω/T (load ρA α x, tip deflection
  // 11 ρA α L⁵/(120 EI) = 0.63 m) less ~10 % centrifugal stiffening bounds the peak from above.
  EXPECT_GT(rich, 0.45);
  EXPECT_LT(rich, 0.63);
  // Without the velocity-product terms the equations are no longer Lagrange's: the same run breaks
  // the energy balance by far more than balance_tol (or fails), so the test catches such a model.
  const Model m = build_model(c, 10);
  ForceTerms no_h;
  no_h.velocity_products = false;
  const Sim bad = simulate(m, {law(spinup_law(0.0, 6.0, 15.0))}, 20.0, no_h);
  RecordProperty("without_h", bad.outcome.status.to_string());
  if (bad.outcome.completed()) {
    EXPECT_GT(energy_balance_drift(bad), 10 * balance_tol * bad.s.back().input_work);
  }
}

TEST(PaperCase, StiffLinkApproachesRigidTorques) {
  auto torque_gap = [&](double scale) {
    const Case s = read_case(test::source_path("cases/paper_deployment.toml"),
                             {"materials.al.E=" + std::to_string(6.895e10 * scale), "materials.al.G=" + std::to_string(2.6519e10 * scale),
                              // (beyond any material at 1e4: meant, and acknowledged)
                              scale > 1 ? R"(case.accept=["sections.B2.J", "materials.al.E", "materials.al.G"])" : "case.accept=[\"sections.B2.J\"]"});
    const Model flex = build_model(s, 6), rigid = rigidify(flex);
    const Sim f = simulate(flex, deployment(), 8.0), r = simulate(rigid, deployment(), 8.0);
    double gap = 0.0, ref = 0.0;
    for (size_t i = 0; i < f.s.size(); ++i) {
      gap = std::max(gap, (f.s[i].tau - r.s[i].tau).lpNorm<Eigen::Infinity>());
      ref = std::max(ref, r.s[i].tau.lpNorm<Eigen::Infinity>());
    }
    return gap / ref;
  };
  const double normal = torque_gap(1.0), stiff = torque_gap(1e4);
  RecordProperty("torque_gap_normal", std::to_string(normal));
  RecordProperty("torque_gap_stiff", std::to_string(stiff));
  EXPECT_LT(stiff, 1e-2);
  EXPECT_LT(stiff, 0.1 * normal);
}

TEST(PaperCase, FlexibilityFeedsBackIntoTheBase) {
  // n = 6 as in the paper: (b) the joint-3 torque of the flexible link differs visibly from the
  // rigid one (Fig. 6); (c) under the rigid torques joint 3 departs from the law (Fig. 7).
  const Case c = read_case(test::source_path("cases/paper_deployment.toml"));
  const Model flex = build_model(c, 6), rigid = rigidify(flex);
  const auto laws = deployment();
  const Sim a = simulate(rigid, laws, 20.0), b = simulate(flex, laws, 20.0);
  double gap = 0.0, ref = 0.0;
  for (size_t i = 0; i < a.s.size(); ++i) {
    gap = std::max(gap, std::abs(b.s[i].tau[2] - a.s[i].tau[2]));
    ref = std::max(ref, std::abs(a.s[i].tau[2]));
  }
  EXPECT_GT(gap, 0.1 * ref) << "flexible vs rigid joint-3 torque";
  const std::vector<JointInput> forces = rigid_torque_inputs(std::make_shared<const Model>(rigid), laws);
  const Sim fr = simulate(flex, forces, 20.0);
  ASSERT_TRUE(fr.outcome.completed()) << fr.outcome.status;
  double dq3 = 0.0;
  for (const auto& x : fr.s) dq3 = std::max(dq3, std::abs(x.q[flex.joint_index(2)] - laws[2].motion->at(x.t).q));
  RecordProperty("joint3_departure_rad", std::to_string(dq3));
  EXPECT_GT(dq3, 1e-3);
}

TEST(PaperCase, PdFeedbackWithComputedTorqueTracksTheDeployment) {
  // cases/paper_pd_tracking.toml: the same arm (n = 6) with PD feedback on every joint plus the
  // rigid computed torque. Open loop (computed torque alone, the paper's force run) joints drift
  // 0.03–0.05 rad off the law; the feedback (about 1 rad/s, critically damped) must hold every
  // joint to 1/20 of its open-loop error, and the energy balance must close with the feedback's
  // work counted as input work (1e-6 of the scale, as for every other input).
  const Case c = read_case(test::source_path("cases/paper_pd_tracking.toml"));
  const Model flex = build_model(c, 6), rigid = rigidify(flex);
  const std::vector<JointInput> pd = joint_inputs(c);
  const auto laws = deployment();
  for (const auto& j : pd) ASSERT_FALSE(j.prescribed());
  const Sim closed = simulate(flex, pd, 20.0), open = simulate(flex, rigid_torque_inputs(std::make_shared<const Model>(rigid), laws), 20.0);
  ASSERT_TRUE(closed.outcome.completed()) << closed.outcome.status;
  ASSERT_TRUE(open.outcome.completed()) << open.outcome.status;
  double drift = 0.0, scale = 0.0;
  for (int j = 0; j < 3; ++j) {
    double e_closed = 0.0, e_open = 0.0;
    for (size_t i = 0; i < closed.s.size(); ++i) {
      const double ref = laws[j].motion->at(closed.s[i].t).q;
      e_closed = std::max(e_closed, std::abs(closed.s[i].q[flex.joint_index(j)] - ref));
      e_open = std::max(e_open, std::abs(open.s[i].q[flex.joint_index(j)] - ref));
    }
    RecordProperty("joint" + std::to_string(j + 1) + "_pd_error_rad", std::to_string(e_closed));
    RecordProperty("joint" + std::to_string(j + 1) + "_open_loop_error_rad", std::to_string(e_open));
    EXPECT_LT(e_closed, e_open / 20.0) << "joint " << j + 1;
    EXPECT_GT(e_open, 1e-2) << "joint " << j + 1 << ": open loop must drift for the test to mean something";
  }
  for (const auto& x : closed.s) {
    const double bal = x.energy.kinetic + x.energy.elastic + x.energy.gravity + x.dissipated - x.input_work;
    const auto& x0 = closed.s.front();
    drift = std::max(drift, std::abs(bal - (x0.energy.kinetic + x0.energy.elastic + x0.energy.gravity)));
    scale = std::max({scale, x.energy.kinetic, std::abs(x.input_work)});
  }
  EXPECT_LT(drift, 1e-6 * scale);
}
