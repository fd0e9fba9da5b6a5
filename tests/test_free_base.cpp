// A free-floating base (core/base_chain.hpp, free_base_joints): six torque-free coordinates of a
// bus carry the chain. Checks: a rotor on a bus follows the exact reaction; the momentum of
// assembly/momentum.hpp is the generalised momentum of the base coordinates (M v); the paper's
// deployment on a free bus keeps linear and angular momentum at zero while the bus moves; the run
// stops with a clear status before the yaw–pitch–roll angles become singular.
#include <gtest/gtest.h>

#include "../assembly/dense_reference.hpp"
#include "../assembly/momentum.hpp"
#include "../simulation/inputs.hpp"
#include "../solvers/integrator.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

IntegratorOptions tight(double t_end, double dt) {
  IntegratorOptions o;
  o.t_end = t_end;
  o.output_dt = dt;
  o.rtol = 1e-9;
  o.atol = 1e-11;
  o.atol_velocity = 1e-9;
  return o;
}

std::vector<OutputSample> run(const Model& m, const std::vector<JointInput>& in, const IntegratorOptions& o,
                              RunOutcome* outcome = nullptr) {
  std::vector<OutputSample> s;
  const RunOutcome r = integrate(m, in, o, [&](const OutputSample& x) { s.push_back(x); });
  if (outcome) *outcome = r;
  else EXPECT_TRUE(r.completed()) << r.status;
  return s;
}

// A uniform body about its own mass centre (pseudo-inertia from the principal inertia I).
Mat4 body(double mass, const Vec3& com, const Vec3& I) {
  Mat4 H = Mat4::Zero();
  const double tr = 0.5 * I.sum();
  for (int a = 0; a < 3; ++a) H(a, a) = tr - I[a] + mass * com[a] * com[a];
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (a != b) H(a, b) = mass * com[a] * com[b];
  H.topRightCorner<3, 1>() = mass * com;
  H.bottomLeftCorner<1, 3>() = mass * com.transpose();
  H(3, 3) = mass;
  return H;
}

}  // namespace

TEST(FreeBase, RotorOnABusFollowsTheExactReaction) {
  // A bus (yaw inertia I_b) and a rotor (I_a) on a joint about the bus's z axis through both mass
  // centres, torque τ from rest: I_b ψ̈ = −τ, I_a (ψ̈ + q̈) = τ, so ψ = −τt²/(2I_b) and
  // q = τt²/2 (1/I_a + 1/I_b); the bus does not translate or tilt. Exact quadratics: the
  // integrator reproduces them to round-off (bound 1e-9 of the rotor angle).
  const double Ib = 40.0, Ia = 10.0, tau = 2.0;
  std::vector<Joint> js = free_base_joints(body(100.0, Vec3::Zero(), Vec3(30.0, 35.0, Ib)));
  Joint rotor;
  rotor.name = "rotor";
  rotor.H = body(5.0, Vec3::Zero(), Vec3(6.0, 6.0, Ia));
  js.push_back(rotor);
  Model m = make_model(js, Mat4::Identity(), Discretisation{}, 0.0);
  m.free_base = true;
  std::vector<JointInput> in(7);
  for (auto& j : in) j.torque = constant_torque(0.0);
  in[6].torque = constant_torque(tau);
  const auto s = run(m, in, tight(3.0, 0.1));
  double worst = 0.0, drift = 0.0;
  for (const auto& x : s) {
    const double t2 = x.t * x.t;
    worst = std::max({worst, std::abs(x.q[3] + tau * t2 / (2 * Ib)), std::abs(x.q[6] - tau * t2 / 2 * (1 / Ia + 1 / Ib))});
    drift = std::max({drift, x.q.head<3>().cwiseAbs().maxCoeff(), std::abs(x.q[4]), std::abs(x.q[5])});
  }
  const double q_end = tau * 9 / 2 * (1 / Ia + 1 / Ib);
  EXPECT_LT(worst, 1e-9 * q_end);
  EXPECT_LT(drift, 1e-12);
  EXPECT_NEAR(s.back().momentum.angular.z(), 0.0, 1e-10 * tau * 3.0);  // vs the rotor's own I_a(ψ̇ + q̇) = τt
}

TEST(FreeBase, MomentumIsTheGeneralisedMomentumOfTheBaseCoordinates) {
  // Every body moves with the base joints, so ∂T/∂q̇_j = (M v)_j is p·u_j for a base translation
  // along u_j and (L − o_j × p)·u_j for a rotation about the axis (o_j, u_j): an independent check
  // of momentum() against the assembled mass matrix at a random deformed, moving state.
  Case cs = read_case(test::source_path("cases/space_deployment.toml"));
  const Model m = build_model(cs, 5);
  VecX q, v, a;
  test::random_state(m, 7, q, v, a);
  const BorderedPattern p(m.n(), m.m());
  std::vector<int> cols(m.m());
  for (int j = 0; j < m.m(); ++j) cols[j] = m.joint_index(j);
  MatrixTerms t;
  t.mass = 1.0;
  std::vector<double> vals;
  assemble_matrix(m, p, cols, q, v, t, vals);
  const VecX Mv = to_dense(p, vals) * v;
  const Momentum P = momentum(m, q, v);
  BaseKinematics bk;
  base_kinematics(m, q, v, VecX::Zero(m.dof()), bk);
  const double scale = P.linear.norm() + P.angular.norm();
  ASSERT_GT(scale, 1.0);
  for (int j = 0; j < free_base_dofs; ++j) {
    const Mat4& W = bk.W[j];  // joint j's frame: its axis is W's rotation times the joint's axis
    const Vec3 u = W.topLeftCorner<3, 3>() * m.joints[j].axis, o = W.topRightCorner<3, 1>();
    const double expected = j < 3 ? P.linear.dot(u) : (P.angular - o.cross(P.linear)).dot(u);
    EXPECT_NEAR(Mv[m.joint_index(j)], expected, 1e-12 * scale) << m.joints[j].name;
  }
}

TEST(FreeBase, DeploymentOnAFreeBusKeepsMomentumZero) {
  // Without gravity nothing outside acts on bus + arm: p and L stay at their initial zero while
  // the bus drifts and turns — with the arm's joints prescribed (their torques come out of the
  // base rows) and with PD feedback on the same laws (force input on every joint). Scale: the
  // momentum the arm's motion alone would carry on a bus held still (the bus rates zeroed), which
  // the bus's reaction must cancel. The integrator runs at rtol 1e-9; 1e-6 of the scale leaves room
  // for its error and fails for any missing coupling.
  Case cs = read_case(test::source_path("cases/space_deployment.toml"), {"simulation.t_end=16"});
  const Model m = build_model(cs, 6);
  const std::vector<JointInput> prescribed = joint_inputs(cs);
  std::vector<JointInput> feedback = prescribed;
  for (int j = free_base_dofs; j < m.m(); ++j) {
    feedback[j].torque = pd_law(prescribed[j].motion, 40.0, 60.0, nullptr);
    feedback[j].motion = nullptr;
  }
  for (const std::vector<JointInput>* inputs : {&prescribed, const_cast<const std::vector<JointInput>*>(&feedback)}) {
    const auto s = run(m, *inputs, tight(16.0, 0.25));
    double worst = 0.0, scale = 0.0, moved = 0.0;
    for (const auto& x : s) {
      const Momentum P = x.momentum;
      worst = std::max({worst, P.linear.norm(), P.angular.norm()});
      VecX held = x.v;
      held.segment<free_base_dofs>(m.joint_index(0)).setZero();
      const Momentum A = momentum(m, x.q, held);
      scale = std::max({scale, A.linear.norm(), A.angular.norm()});
      moved = std::max(moved, x.q.segment<free_base_dofs>(m.joint_index(0)).cwiseAbs().maxCoeff());
    }
    const std::string what = inputs == &prescribed ? "prescribed" : "feedback";
    char ratio[32];
    std::snprintf(ratio, sizeof ratio, "%.2e", worst / scale);
    RecordProperty("momentum_over_scale_" + what, ratio);
    EXPECT_LT(worst, 1e-6 * scale) << what << ": scale " << scale;
    EXPECT_GT(moved, 0.05) << what << ": the bus must react visibly";
  }
}

TEST(FreeBase, RunStopsBeforeTheAnglesBecomeSingular) {
  // A bus tumbling in pitch at 0.5 rad/s passes 85° after 1.7 s: the run fails there with a status
  // that names the pitch, keeping the outputs before.
  Case cs = read_case(test::source_path("cases/space_deployment.toml"),
                      {"base.pitch_rate=0.5", "simulation.t_end=4", "simulation.initial=undeformed"});
  const Model m = build_model(cs, 2);
  RunOutcome r;
  IntegratorOptions o = tight(4.0, 0.05);
  o.initial = InitialState::Undeformed;
  const auto s = run(m, joint_inputs(cs), o, &r);
  EXPECT_FALSE(r.completed());
  EXPECT_NE(r.status.to_string().find("pitch"), std::string::npos) << r.status;
  ASSERT_FALSE(s.empty());
  EXPECT_GT(s.back().t, 1.5);
  EXPECT_LT(std::abs(s.back().q[m.joint_index(free_base_pitch)]), free_base_pitch_limit);
}
