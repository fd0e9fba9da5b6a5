// Several flexible links: a link mounted on another's tip through a locked
// joint is the same beam as one link of the combined length; the two-link flexible arm conserves
// energy (and friction accounts for the loss), its kinematic torques reproduce its motion as force
// input, on a free bus it keeps momentum and centre of mass, and its frequencies converge at
// second order in n.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <iomanip>
#include <limits>
#include <sstream>

#include "../assembly/momentum.hpp"
#include "../simulation/inputs.hpp"
#include "../solvers/integrator.hpp"
#include "../solvers/modes.hpp"
#include "../solvers/statics.hpp"
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

namespace {

std::vector<OutputSample> run(const Model& m, const std::vector<JointInput>& in, double t_end, double dt,
                              double rtol = 1e-9) {
  IntegratorOptions o;
  o.t_end = t_end;
  o.output_dt = dt;
  o.rtol = rtol;
  o.atol = 1e-11;
  o.atol_velocity = 1e-8;
  std::vector<OutputSample> s;
  const RunOutcome r = integrate(m, in, o, [&](const OutputSample& x) { s.push_back(x); });
  EXPECT_TRUE(r.completed()) << r.status;
  return s;
}

JointInput torque_free(double q0, double v0) {
  JointInput j;
  j.torque = constant_torque(0.0);
  j.q0 = q0;
  j.v0 = v0;
  return j;
}

double balance(const OutputSample& x) {
  return x.energy.kinetic + x.energy.elastic + x.energy.gravity + x.dissipated - x.input_work;
}

}  // namespace

TEST(Links, TwoLinkArmConservesEnergyAndFrictionAccountsForTheLoss) {
  // cases/two_link_arm.toml (n = 16), set swinging by initial joint rates and left alone. Without
  // sde damping and drives T + V is constant; with the case's sde damping, viscous and smoothed
  // Coulomb friction in both drives T + V + dissipated is, and the dissipated energy is a large
  // part of the initial energy (a missing loss would break the balance by that much). The
  // integrator runs at rtol 1e-9: 1e-6 of the energy leaves room for its error, not for a term.
  const Case c = read_case(test::source_path("cases/two_link_arm.toml"));
  const Model lossy = build_model(c, 16);
  Model clean = lossy;
  for (auto& L : clean.links) L.d.damping_beta = 0.0;
  for (auto& j : clean.joints) j.drive = JointDrive{};
  const std::vector<JointInput> in{torque_free(0.0, 1.5), torque_free(0.0, -2.0)};
  for (const Model* m : {static_cast<const Model*>(&clean), &lossy}) {
    const auto s = run(*m, in, 3.0, 0.01);
    const double E0 = s.front().energy.kinetic;
    double drift = 0.0;
    for (const auto& x : s) drift = std::max(drift, std::abs(balance(x) - balance(s.front())));
    const std::string what = m == &clean ? "undamped" : "damped";
    RecordProperty("energy_drift_over_E0_" + what, fmt(drift / E0));
    EXPECT_LT(drift, 1e-6 * E0) << what;
    if (m == &lossy) {
      RecordProperty("dissipated_over_E0", fmt(s.back().dissipated / E0));
      EXPECT_GT(s.back().dissipated, 0.1 * E0) << "friction and damping must take a visible part";
    } else {
      EXPECT_EQ(s.back().dissipated, 0.0);
    }
  }
}

TEST(Links, KinematicTorquesAsForceInputReproduceTheMotionOfTwoFlexibleLinks) {
  // docs/formulation.md §7 invariant 7 on the two-link arm (both links flexible, the elbow on the upper
  // link's tip): the torques of a kinematic-input run, as a cubic spline through 1 kHz samples,
  // drive the arm back along the prescribed motion. Drives without friction (its tanh makes the
  // torque kink at rest); sde damping β = 1e-4 s as in the case. Both runs' errors (rtol 1e-9)
  // grow at most like t² on the free joints; a wrong torque — any missing coupling between the
  // links — puts errors of 1e-2 rad here.
  const Case c = read_case(test::source_path("cases/two_link_arm.toml"));
  Model m = build_model(c, 12);
  for (auto& j : m.joints) j.drive.friction = 0.0;
  std::vector<JointInput> laws(2);
  laws[0].motion = deployment_law(0.0, -0.6667, 2.0);
  laws[1].motion = deployment_law(0.0, 1.0, 2.0);
  const auto kin = run(m, laws, 2.5, 1e-3);
  std::vector<JointInput> forces;
  for (int j = 0; j < 2; ++j) {
    std::vector<double> t, tau;
    for (const auto& x : kin) {
      t.push_back(x.t);
      tau.push_back(x.tau[j]);
    }
    JointInput f = torque_free(0.0, 0.0);
    f.torque = spline_torque(t, tau);
    forces.push_back(f);
  }
  const auto frc = run(m, forces, 2.5, 1e-3);
  double worst = 0.0, bend = 0.0;
  for (size_t i = 0; i < frc.size(); ++i) {
    for (int j = 0; j < 2; ++j) worst = std::max(worst, std::abs(frc[i].q[m.joint_index(j)] - laws[j].motion->at(frc[i].t).q));
    bend = std::max(bend, std::abs(tip_motion(m, 0, kin[i].q)[1]));
  }
  RecordProperty("round_trip_error_rad", fmt(worst));
  EXPECT_LT(worst, 1e-5);
  EXPECT_GT(bend, 1e-3) << "the upper link must bend visibly for the test to mean something";
}

TEST(Links, TwoFlexibleLinksOnAFreeBusKeepMomentumAndCentreOfMass) {
  // The two-link arm on a free-floating 20 kg bus (no gravity): the joints' PD torques are
  // internal, so linear and angular momentum stay zero and the centre of mass stays put while the
  // bus recoils. Scale: the momentum the arm's motion alone would carry on a bus held still;
  // 1e-6 of it leaves room for the integrator (rtol 1e-9), not for a missing coupling.
  const Case c = read_case(test::source_path("cases/two_link_arm.toml"),
                           {"base.kind=free", "base.body.mass=20.0", "base.body.inertia=[0.4, 0.4, 0.6, 0, 0, 0]",
                            "joints.0.input.feedforward=none", "joints.1.input.feedforward=none"});
  const Model m = build_model(c, 12);
  ASSERT_TRUE(m.free_base);
  const auto s = run(m, joint_inputs(c), 3.0, 0.02);
  double worst = 0.0, scale = 0.0, moved = 0.0, drift = 0.0;
  for (const auto& x : s) {
    worst = std::max({worst, x.momentum.linear.norm(), x.momentum.angular.norm()});
    VecX held = x.v;
    held.segment<free_base_dofs>(m.joint_index(0)).setZero();
    const Momentum A = momentum(m, x.q, held);
    scale = std::max({scale, A.linear.norm(), A.angular.norm()});
    moved = std::max(moved, x.q.segment<3>(m.joint_index(0)).norm());
    drift = std::max(drift, (x.momentum.centre - s.front().momentum.centre).norm());
  }
  RecordProperty("momentum_over_scale", fmt(worst / scale));
  RecordProperty("centre_drift_over_bus_motion", fmt(drift / moved));
  EXPECT_LT(worst, 1e-6 * scale);
  EXPECT_GT(moved, 1e-3) << "the bus must recoil";
  EXPECT_LT(drift, 1e-6 * moved);
}

TEST(Links, FrequenciesOfATreeConvergeAtSecondOrder) {
  // The two-link arm with the elbow bent 90 deg, both joints held: its lowest modes couple the
  // two links through the elbow. The discretisation error of the RFEM falls as 1/n²: the observed
  // order from n = 16, 32, 64 (in all) must be 2 to within the 1/n⁴ term.
  const Case c = read_case(test::source_path("cases/two_link_arm.toml"), {"joints.1.value=\"90 deg\""});
  const VecX qb = c.joint_values, none(0);
  std::vector<VecX> w;
  for (int n : {16, 32, 64}) w.push_back(compute_modes(build_model(c, n), qb, none, 3).omega);
  for (int i = 0; i < 3; ++i) {
    const double p = std::log(std::abs(w[1][i] - w[0][i]) / std::abs(w[2][i] - w[1][i])) / std::log(2.0);
    RecordProperty("order_mode" + std::to_string(i + 1), fmt(p));
    EXPECT_NEAR(p, 2.0, 0.1) << "mode " << i + 1;
  }
}

TEST(Links, OneLinkAtTheEndOfTheChainIsAsBeforeTopologies) {
  // No regression: one flexible link at the end of a serial chain — the paper's
  // deployment (kinematic input, n = 6) and the same arm on a free bus — against values printed by
  // rfem 4a88975, before links and joints could be mounted on one another. The stored values carry
  // the default tolerances' integration error: 6.6e-6 of a series' peak (paper) and 1.1e-6 (free
  // bus) against the same runs at rtol 1e-12, atol 1e-14. A run of today carries its own, of the
  // same size, and any change of the step control moves it within that (the Newton matrix at the
  // step's middle: 1.7e-6); the bound, 2e-5 of each series' peak, is the two together with room,
  // and far below what a change of the model moves (a mounting error: the whole motion).
  struct Expect {
    double t;
    std::array<double, 3> u, y;  // tip deflection; joint torques (paper) or base x, y, z (free bus)
  };
  const std::vector<Expect> paper = {
      {5.0, {0.030426316314085995, 0.0007930210008227961, 0.001135154957440398}, {0.09217985433515101, -2.3251594708254597, -2.6322876474029324}},
      {10.0, {-0.028428584067014092, 0.006443711695822857, 0.011793557754191393}, {-0.4391794433004264, 1.8716152387583154, 2.643871803723572}},
      {15.0, {0.00040026716674783705, 0.0001230839732924309, 0.00022547143393645321}, {-0.010067834978327556, -0.025009952971288708, -0.024985388940504595}},
      {20.0, {-0.00461993075259429, -0.0007439695778096775, -0.0012946846642617593}, {0.06748223978554982, 0.3045943281388316, 0.30497627423703605}}};
  const std::vector<Expect> space = {
      {5.0, {0.026561220076885626, 0.0006450033997706309, 0.0008699059465638577}, {0.044586815246103535, -0.006077748910064522, 0.00574842280856559}},
      {10.0, {-0.02854074521202773, 0.005537493534174962, 0.010179599789934456}, {0.13029889370455877, -0.037800690464100666, -0.003784505211239265}},
      {20.0, {0.0011896603434945717, -4.817410352544911e-05, -7.02552715071577e-05}, {0.15486322695656407, -0.060594148037268834, -0.017916252251482186}}};
  for (const bool bus : {false, true}) {
    const Case c = read_case(test::source_path(bus ? "cases/space_deployment.toml" : "cases/paper_deployment.toml"));
    const Model m = build_model(c, 6);
    IntegratorOptions o = c.sim.options;
    std::vector<OutputSample> s;
    ASSERT_TRUE(integrate(m, joint_inputs(c), o, [&](const OutputSample& x) { s.push_back(x); }).completed());
    const std::vector<Expect>& want = bus ? space : paper;
    std::array<double, 6> peak{};  // of each series in the stored values' run (a floor for zeros)
    for (const auto& x : s)
      for (int i = 0; i < 3; ++i) {
        peak[i] = std::max(peak[i], std::abs(tip_motion(m, 0, x.q)[1 + i]));
        peak[3 + i] = std::max(peak[3 + i], std::abs(bus ? x.q[m.joint_index(i)] : x.tau[i]));
      }
    double worst = 0.0;
    for (const Expect& e : want) {
      const auto& x = *std::min_element(s.begin(), s.end(), [&](const auto& a, const auto& b) {
        return std::abs(a.t - e.t) < std::abs(b.t - e.t);
      });
      const Vec6 tip = tip_motion(m, 0, x.q);
      for (int i = 0; i < 3; ++i) {
        const double y = bus ? x.q[m.joint_index(i)] : x.tau[i];
        worst = std::max({worst, std::abs(tip[1 + i] - e.u[i]) / peak[i], std::abs(y - e.y[i]) / peak[3 + i]});
      }
    }
    RecordProperty(bus ? "free_bus_difference_over_peak" : "paper_difference_over_peak", fmt(worst));
    EXPECT_LT(worst, 2e-5) << (bus ? "free bus" : "paper deployment");
  }
}
