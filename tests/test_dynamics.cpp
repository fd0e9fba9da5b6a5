// Time integration (docs/formulation.md §7 invariants 3, 4, 7, 9): energy is conserved without damping,
// gravity or input, and the balance T + V + dissipated − input work closes with them; angular
// momentum about a free vertical joint is conserved; torques of a kinematic-input run applied as
// force input reproduce the prescribed motion; 1 and 2 threads agree; the Schur/CHOLMOD Newton solve
// equals a dense solve of the full 2N system.
#include <gtest/gtest.h>
#include <omp.h>

#include <filesystem>

#include "../assembly/dense_reference.hpp"
#include "../solvers/integrator.hpp"
#include "../solvers/newton_system.hpp"
#include "../solvers/reduction.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

struct Trace {
  std::vector<OutputSample> s;
};

Trace run(const Model& m, const std::vector<JointInput>& in, IntegratorOptions o) {
  Trace tr;
  const RunOutcome r = integrate(m, in, o, [&](const OutputSample& x) { tr.s.push_back(x); });
  EXPECT_TRUE(r.completed()) << r.status;
  std::printf("  t_end %.2f: %ld steps, %ld residuals, %ld factorisations\n", o.t_end, r.stats.steps,
              r.stats.residual_evals, r.stats.factorizations);
  return tr;
}

IntegratorOptions tight(double t_end) {
  IntegratorOptions o;
  o.t_end = t_end;
  o.output_dt = 0.01;
  o.rtol = 1e-8;
  o.atol = 1e-10;
  o.atol_velocity = 1e-8;
  return o;
}

JointInput free_joint(double q0, double v0, double tau = 0.0) {
  JointInput j;
  j.torque = constant_torque(tau);
  j.q0 = q0;
  j.v0 = v0;
  return j;
}

JointInput law(std::shared_ptr<MotionLaw> m) {
  JointInput j;
  j.motion = std::move(m);
  j.q0 = j.motion->at(0).q;
  j.v0 = j.motion->at(0).qd;
  return j;
}

std::string sci(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3e", x);
  return b;
}

double balance(const OutputSample& x) {
  return x.energy.kinetic + x.energy.elastic + x.energy.gravity + x.dissipated - x.input_work;
}

}  // namespace

TEST(Dynamics, EnergyConservedWithoutDampingGravityOrInput) {
  Model m = test::spatial_arm(6);
  m.gravity = 0.0;
  const Trace tr = run(m, {free_joint(0.2, 1.0), free_joint(-0.3, -0.8)}, tight(1.0));
  const double E0 = balance(tr.s.front());
  double drift = 0.0;
  for (const auto& x : tr.s) drift = std::max(drift, std::abs(balance(x) - E0));
  // BDF2 at rtol 1e-8 damps the (tiny) energy of the sde modes it steps over; 1e-6 of the total
  // energy bounds that, while a wrong inertial or elastic term changes E by O(1).
  EXPECT_LT(drift / E0, 1e-6) << "E0 = " << E0;
  RecordProperty("relative_energy_drift", std::to_string(drift / E0));
}

TEST(Dynamics, EnergyBalanceClosesWithDampingGravityAndInputs) {
  const Model m = test::spatial_arm(6, 2e-3);
  const Trace tr = run(m, {law(deployment_law(0.0, 0.5, 2.0)), free_joint(0.4, 0.0, 3.0)}, tight(2.0));
  double drift = 0.0, scale = 0.0;
  for (const auto& x : tr.s) {
    drift = std::max(drift, std::abs(balance(x) - balance(tr.s.front())));
    scale = std::max({scale, x.energy.kinetic, std::abs(x.input_work), x.dissipated});
  }
  EXPECT_GT(tr.s.back().dissipated, 1e-6 * scale) << "the case must dissipate";
  EXPECT_LT(drift / scale, 1e-6);
}

TEST(Dynamics, EnergyBalanceClosesWithJointDrives) {
  // Rotor inertia, viscous damping and smoothed Coulomb friction on a prescribed and a free joint
  // (v_s well inside the motion's rates, so the friction switches sign through its steep part):
  // the dissipated energy must account for the drives' loss exactly as for the sdes'. The link is
  // undamped, so the drives are all that dissipates.
  Model m = test::spatial_arm(6);
  m.joints[0].drive = {0.05, 0.3, 0.2, 0.05};
  m.joints[1].drive = {0.02, 0.1, 0.3, 0.02};
  IntegratorOptions o = tight(2.0);
  o.atol_velocity = IntegratorOptions{}.atol_velocity;  // the default: the undamped sde modes are not resolved
  const Trace tr = run(m, {law(deployment_law(0.0, 0.5, 2.0)), free_joint(0.4, 0.0, 3.0)}, o);
  double drift = 0.0, scale = 0.0;
  for (const auto& x : tr.s) {
    drift = std::max(drift, std::abs(balance(x) - balance(tr.s.front())));
    scale = std::max({scale, x.energy.kinetic, std::abs(x.input_work), x.dissipated});
  }
  RecordProperty("relative_drift", sci(drift / scale));
  RecordProperty("dissipated_over_scale", sci(tr.s.back().dissipated / scale));
  EXPECT_GT(tr.s.back().dissipated, 0.05 * scale) << "the drives must dissipate a visible share";
  EXPECT_LT(drift / scale, 1e-6);
}

TEST(Dynamics, DrivenJointReachesTheExactSpinUp) {
  // Kane's beam made rigid on its hub: one vertical joint of inertia I (the beam) plus the rotor's
  // J, viscous damping c, constant torque τ from rest: ω(t) = (τ/c)(1 − exp(−c t / (I + J))).
  // The integrator runs at rtol 1e-8; 1e-6 of τ/c would be exceeded by a drive term of wrong size
  // (J or c off by 1e-4 changes ω by ~1e-5 of τ/c over this run).
  Case cs = read_case(test::source_path("cases/kane_spinup.toml"));
  Model m = rigidify(build_model(cs, 4));
  const double J = 500.0, c = 40.0, tau = 200.0;
  m.joints[0].drive = {J, c, 0.0, 1e-3};
  const BorderedPattern p(0, 1);
  MatrixTerms tm;
  tm.mass = 1.0;
  std::vector<double> vals;
  Model bare = m;
  bare.joints[0].drive = {};
  assemble_matrix(bare, p, {0}, VecX::Zero(1), VecX::Zero(1), tm, vals);
  const double I = to_dense(p, vals)(0, 0);
  IntegratorOptions o = tight(30.0);
  o.output_dt = 0.5;
  const Trace tr = run(m, {free_joint(0.0, 0.0, tau)}, o);
  double worst = 0.0;
  for (const auto& x : tr.s) worst = std::max(worst, std::abs(x.v[0] - tau / c * (1.0 - std::exp(-c * x.t / (I + J)))));
  RecordProperty("max_error_over_tau_c", sci(worst / (tau / c)));
  EXPECT_LT(worst, 1e-6 * tau / c) << "I = " << I;
  EXPECT_GT(tr.s.back().v[0], 0.3 * tau / c) << "the run must spin up visibly";
  // With Coulomb friction F_c as well, the rate settles where τ = c ω + F_c tanh(ω / v_s).
  const double Fc = 60.0, vs = 0.01;
  m.joints[0].drive = {J, c, Fc, vs};
  o.t_end = 400.0;
  o.output_dt = 10.0;
  const Trace tf = run(m, {free_joint(0.0, 0.0, tau)}, o);
  double w = (tau - Fc) / c;
  for (int i = 0; i < 50; ++i) {  // Newton on g(ω) = c ω + F_c tanh(ω/v_s) − τ
    const double ch = std::cosh(w / vs);
    w -= (c * w + Fc * std::tanh(w / vs) - tau) / (c + Fc / (vs * ch * ch));
  }
  EXPECT_NEAR(tf.s.back().v[0], w, 1e-6 * w);
}

TEST(Dynamics, PdFeedbackGivesTheExactStepResponse) {
  // The rigid hub of Kane's beam (inertia I) under PD feedback to a fixed reference q_ref = 1 rad
  // from rest at 0: I q̈ + kd q̇ + kp q = kp q_ref, an underdamped second-order step response
  // q = 1 − e^{−ζωt}(cos ω_d t + ζ/√(1−ζ²) sin ω_d t). Gains in the feedback's Newton terms only
  // speed the iteration, so a wrong sign or size shows in the response, not in convergence:
  // the bound 1e-6 rad sits far below what a 1e-4 error in kp or kd changes (~1e-5 rad).
  Case cs = read_case(test::source_path("cases/kane_spinup.toml"));
  const Model m = rigidify(build_model(cs, 4));
  const BorderedPattern p(0, 1);
  MatrixTerms tm;
  tm.mass = 1.0;
  std::vector<double> vals;
  assemble_matrix(m, p, {0}, VecX::Zero(1), VecX::Zero(1), tm, vals);
  const double I = to_dense(p, vals)(0, 0), w = 0.8, zeta = 0.3, kp = I * w * w, kd = 2 * zeta * w * I;
  JointInput j;
  j.torque = pd_law(constant_rate_law(1.0, 0.0), kp, kd, nullptr);
  IntegratorOptions o = tight(20.0);
  o.output_dt = 0.1;
  const Trace tr = run(m, {j}, o);
  const double wd = w * std::sqrt(1 - zeta * zeta);
  double worst = 0.0, peak = 0.0;
  for (const auto& x : tr.s) {
    const double q = 1 - std::exp(-zeta * w * x.t) * (std::cos(wd * x.t) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(wd * x.t));
    worst = std::max(worst, std::abs(x.q[0] - q));
    peak = std::max(peak, x.q[0]);
  }
  RecordProperty("max_error_rad", sci(worst));
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(peak, 1.3) << "an underdamped loop overshoots (ζ = 0.3: 37 %)";
  // (The energy balance with feedback is checked on the paper's arm, PaperCase.PdFeedback…: here the
  // steps, 0.17 s, are longer than the outputs, and the energy integrals between step ends are
  // cubic Hermite interpolants, good to ~5e-6 of the energy at this step size.)
}

TEST(Dynamics, AngularMomentumAboutFreeVerticalJointIsConserved) {
  const Model m = test::spatial_arm(5, 1e-3);  // joint 1 turns about the vertical z0; gravity on
  const Trace tr = run(m, {free_joint(0.0, 0.7), law(deployment_law(0.3, 0.5, 1.5))}, tight(2.0));
  const BorderedPattern p(m.n(), m.m());
  std::vector<int> cols{m.flexible_dofs(), m.joint_index(1)};
  auto Lz = [&](const OutputSample& x) {  // ∂T/∂q̇1 = (M v)_1
    MatrixTerms t;
    t.mass = 1.0;
    std::vector<double> vals;
    assemble_matrix(m, p, cols, x.q, x.v, t, vals);
    return (to_dense(p, vals) * x.v)[m.flexible_dofs()];
  };
  const double L0 = Lz(tr.s.front());
  double worst = 0.0;
  for (size_t i = 0; i < tr.s.size(); i += 10) worst = std::max(worst, std::abs(Lz(tr.s[i]) - L0));
  EXPECT_LT(worst, 1e-6 * std::abs(L0)) << "L0 = " << L0;
  // and joint 1 really reacts to joint 2's motion (the test is not trivially satisfied)
  double dv = 0.0;
  for (const auto& x : tr.s) dv = std::max(dv, std::abs(x.v[m.flexible_dofs()] - 0.7));
  EXPECT_GT(dv, 1e-2);
}

TEST(Dynamics, KinematicTorquesAsForceInputReproduceTheMotion) {
  // Light sde damping (β = 1e-3 s) overdamps the axial and shear sde modes (ω ~ 5e3 rad/s) and no
  // gravity lets the link start in equilibrium, so the required torques are smooth enough to be
  // sampled at 1 kHz (the error is then independent of the sampling: 4e-7 rad at 1 and 0.25 ms).
  Model m = test::spatial_arm(4, 1e-3);
  m.gravity = 0.0;  // start in equilibrium: undeformed and at rest
  const std::vector<JointInput> laws{law(deployment_law(0.0, 0.5, 1.0)), law(deployment_law(0.5, -0.75, 1.0))};
  IntegratorOptions o = tight(1.0);
  o.output_dt = 1e-3;
  const Trace kin = run(m, laws, o);
  std::vector<JointInput> forces;
  for (int j = 0; j < 2; ++j) {
    std::vector<double> t, tau;
    for (const auto& x : kin.s) {
      t.push_back(x.t);
      tau.push_back(x.tau[j]);
    }
    // A cubic spline of the sampled torque (error ~ (ω Δt)⁴ of the link's vibration, ≪ tolerance).
    auto spline = tabulated_motion(t, tau);
    JointInput f = free_joint(laws[j].q0, laws[j].v0);
    f.torque = torque_function([spline](double s) { return spline->at(s).q; });
    forces.push_back(f);
  }
  const Trace frc = run(m, forces, o);
  double worst = 0.0;
  for (size_t i = 0; i < frc.s.size(); ++i)
    for (int j = 0; j < 2; ++j) worst = std::max(worst, std::abs(frc.s[i].q[m.joint_index(j)] - laws[j].motion->at(frc.s[i].t).q));
  // Open-loop: errors of both runs (rtol 1e-8) grow at most like t² on the free joints; a wrong
  // torque (any missing term) gives errors of order 1e-2 rad here.
  EXPECT_LT(worst, 1e-5);
  RecordProperty("round_trip_error_rad", std::to_string(worst));
}

TEST(Dynamics, OneAndTwoThreadsAgree) {
  // Bit-identical trajectories: every parallel path on (chunks of 4 rfes, both sweeps of the chain
  // solver), with 1 and 2 threads, for both integrators.
  Model m = test::spatial_arm(40);
  m.gravity = 0.0;
  for (IntegratorKind kind : {IntegratorKind::Esdirk, IntegratorKind::Bdf}) {
    IntegratorOptions o;  // determinism, not accuracy, is tested: default tolerances
    o.kind = kind;
    o.t_end = 0.3;
    o.parallel.min_rfes = 1;
    o.parallel.chunk = 4;
    std::vector<VecX> q1, q2;
    o.parallel.threads = 1;
    for (const auto& x : run(m, {free_joint(0, 1.0), free_joint(0, 0.5, 1.0)}, o).s) q1.push_back(x.q);
    o.parallel.threads = 2;
    for (const auto& x : run(m, {free_joint(0, 1.0), free_joint(0, 0.5, 1.0)}, o).s) q2.push_back(x.q);
    ASSERT_EQ(q1.size(), q2.size());
    for (size_t i = 0; i < q1.size(); ++i)
      EXPECT_EQ((q1[i] - q2[i]).lpNorm<Eigen::Infinity>(), 0.0) << integrator_name(kind) << " output " << i;
  }
}

TEST(Dynamics, SchurSolveEqualsDenseSolveOfFullNewtonSystem) {
  const Model m = test::spatial_arm(5, 3e-3);
  VecX q, v, a;
  test::random_state(m, 31, q, v, a);
  q.head(m.flexible_dofs()) *= 1e-3;  // a physical deformation: the random 5 cm would buckle the axial springs
  const int N = m.dof();
  NewtonSystem ns(std::make_shared<const Model>(m), {m.flexible_dofs(), m.joint_index(1)}, LinearSolverKind::Chain, true);
  const double c = 350.0;
  Workspace ws;
  ASSERT_TRUE(ns.setup(q, v, 1.0 / c, ws));
  const MatX M = dense_mass_matrix(m, q), C = dense_damping(m, q, v), K = dense_stiffness(m, q, false);
  MatX J = MatX::Zero(2 * N, 2 * N);
  J.topLeftCorner(N, N) = c * MatX::Identity(N, N);
  J.topRightCorner(N, N) = -MatX::Identity(N, N);
  J.bottomLeftCorner(N, N) = K;
  J.bottomRightCorner(N, N) = C + c * M;
  VecX b(2 * N);
  b << a, v;
  VecX x(2 * N);
  ns.solve_bdf(b.data(), x.data());
  const VecX ref = J.fullPivLu().solve(b);
  EXPECT_LT((x - ref).norm() / ref.norm(), 1e-10);
}

TEST(Dynamics, StaticInitialStateStartsInEquilibrium) {
  // Joints held still under gravity: started in static equilibrium (the default) the link does not
  // move and the holding torques are constant; started undeformed it falls into a vibration whose
  // torque spike at t = 0 grows with n (it reached 595 N m against ~60 N m on a two-joint arm).
  const Model m = test::spatial_arm(12);
  std::vector<JointInput> hold{law(constant_rate_law(0.3, 0.0)), law(constant_rate_law(-0.4, 0.0))};
  auto span = [&](InitialState init, double& dq, double& dtau) {
    IntegratorOptions o = tight(0.5);
    o.initial = init;
    const Trace tr = run(m, hold, o);
    dq = dtau = 0.0;
    for (const auto& x : tr.s) {
      dq = std::max(dq, (x.q - tr.s.front().q).lpNorm<Eigen::Infinity>());
      dtau = std::max(dtau, (x.tau - tr.s.front().tau).lpNorm<Eigen::Infinity>());
    }
    return tr.s.front().tau.lpNorm<Eigen::Infinity>();
  };
  double dq_s, dtau_s, dq_u, dtau_u;
  const double tau = span(InitialState::Static, dq_s, dtau_s);
  span(InitialState::Undeformed, dq_u, dtau_u);
  RecordProperty("static_torque_change", std::to_string(dtau_s / tau));
  RecordProperty("undeformed_torque_change", std::to_string(dtau_u / tau));
  // At rest in equilibrium: changes at the integrator's tolerance (rtol 1e-8) only.
  EXPECT_LT(dtau_s, 1e-6 * tau);
  EXPECT_LT(dq_s, 1e-8);
  // Undeformed: the sag develops (mm) and the torques swing by a sizeable fraction.
  EXPECT_GT(dq_u, 1e-4);
  EXPECT_GT(dtau_u, 1e-2 * tau);
}

namespace {
long process_threads() {  // the threads of this process now (Linux)
  long n = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/task")) ++n;
  return n;
}
}  // namespace

TEST(Dynamics, AReducedLinksSetupKeepsToTheCallersThreads) {
  // A reduced link's modes and derivatives (statics, assembly, the differences of the static
  // forces) run on the threads the caller's Parallelism allows: libgomp starts its workers at the
  // first region with a team above one and keeps them, so one thread leaves the process's thread
  // count as it was. The same setup with OpenMP's default team (two cores) starts them: what this
  // test watches can fail. (ctest runs each test in a process of its own, with no team before.)
  if (omp_get_max_threads() < 2 || !std::filesystem::exists("/proc/self/task")) GTEST_SKIP() << "one core, or no /proc";
  const Case cs = read_case(test::source_path("cases/paper_deployment.toml"), {"link.modes=4", "link.derivatives=1"});
  const Model model = build_model(cs, 300);  // (teams from 256 rfes on)
  const VecX qb = VecX::Zero(model.m());
  const long before = process_threads();
  if (before > 1) GTEST_SKIP() << "a team started before this test (run it alone: ctest does)";
  Parallelism one;
  one.threads = 1;
  const Reduction mine(model, qb, one);
  EXPECT_EQ(process_threads(), before) << "the setup started threads with Parallelism::threads = 1";
  const Reduction any(model, qb);
  EXPECT_GT(process_threads(), before) << "OpenMP's default team started no thread: the check above cannot fail";
  EXPECT_EQ(mine.rfe(), any.rfe());
}

namespace {
// A reduced Newton matrix's shape: a kept block T, tridiagonal (a reduced link's x1 chain; with
// `wide`, pentadiagonal: links kept whole, by the sparse LDLᵀ), bordered by nb dense columns (its
// modal coordinates and the joints); symmetric, with eigenvalues shifted by `shift` from a positive
// definite start.
SparseMat bordered_matrix(int kept, int nb, double shift, MatX& dense, bool wide = false) {
  const int n = kept + nb;
  std::srand(7);
  MatX A = MatX::Zero(n, n);
  for (int i = 0; i < kept; ++i) {
    A(i, i) = 4.0;
    if (i + 1 < kept) A(i, i + 1) = A(i + 1, i) = -1.0 + 0.1 * (i % 3);
    if (wide && i + 2 < kept) A(i, i + 2) = A(i + 2, i) = 0.3;
  }
  const MatX B = 0.2 * MatX::Random(kept, nb), D = MatX::Random(nb, nb);
  A.topRightCorner(kept, nb) = B;
  A.bottomLeftCorner(nb, kept) = B.transpose();
  A.bottomRightCorner(nb, nb) = D * D.transpose() + double(nb) * MatX::Identity(nb, nb);
  A.diagonal().array() -= shift;
  dense = A;
  SparseMat S = A.sparseView();
  S.makeCompressed();
  return S;
}
}  // namespace

TEST(Dynamics, ReducedFactorSolvesItsBorderedSystemsAsADenseSolve) {
  // The reduced Newton matrix is factorised by its Schur complement (T sparse, the border dense):
  // its solutions equal a dense LDLᵀ's to round-off of a matrix with condition ~10² (1e-12 allows
  // 1e4 ulps), on one and two threads with the same bits; an indefinite matrix is refused as a
  // Newton matrix and solved as a statics' stiffness. T tridiagonal (its own elimination) and not.
  for (const int kept : {0, 60, -60}) {
    MatX A;
    const bool wide = kept < 0;
    const SparseMat S = bordered_matrix(std::abs(kept), 7, 0.0, A, wide);
    const VecX b = VecX::LinSpaced(std::abs(kept) + 7, -1.0, 2.0);
    const VecX exact = A.ldlt().solve(b);
    VecX x1 = b, x2 = b;
    ReducedFactor f1, f2;
    ASSERT_TRUE(f1.factorize(S, std::abs(kept), true, 1));
    ASSERT_TRUE(f2.factorize(S, std::abs(kept), true, 2));
    f1.solve(x1, 1);
    f2.solve(x2, 2);
    EXPECT_LT((x1 - exact).norm(), 1e-12 * exact.norm()) << "kept " << kept;
    EXPECT_EQ(x1, x2) << "one and two threads differ, kept " << kept;
  }
  for (const bool wide : {false, true}) {
    MatX A;
    const SparseMat S = bordered_matrix(60, 7, 3.5, A, wide);  // T's diagonal 0.5: indefinite overall
    ASSERT_LT(Eigen::SelfAdjointEigenSolver<MatX>(A).eigenvalues()[0], 0.0);
    ReducedFactor f;
    EXPECT_FALSE(f.factorize(S, 60, true)) << "an indefinite Newton matrix was taken";
    ASSERT_TRUE(f.factorize(S, 60, false));
    const VecX b = VecX::Ones(67);
    VecX x = b;
    f.solve(x);
    EXPECT_LT((A * x - b).norm(), 1e-10 * b.norm()) << "wide " << wide;
  }
}

TEST(Dynamics, AStagesResidualIsTheResidualOfItsStates) {
  // An ESDIRK stage's residual (EquationsOfMotion::stage_residual) lifts a reduced link's Qk and Vk
  // once and its accelerations A at each Newton iteration: it must be the residual of the stage's
  // Q = Qk + (hγ)² A, V = Vk + hγ A. Without a reduced link it is the very same computation; with
  // one, the lifted coordinates differ from a direct lift by the rounding of Qk + (hγ)² Φ A against
  // Φ (ηk + (hγ)² A) (an ulp of each coordinate), which the stiff sdes carry into the residual at
  // most as K·ulp(q) against ‖K q‖: 1e-12 of ‖r‖ (measured 4e-17). The states of twice the step
  // (hγ doubled) move r by 7e-4 of it.
  for (const int modes : {0, 3}) {
    Model m = test::spatial_arm(8);
    for (MountedLink& L : m.links) {
      L.d.modes = modes;
      L.d.derivatives = modes ? 2 : 0;
    }
    const auto model = std::make_shared<const Model>(std::move(m));
    std::vector<JointInput> inputs(model->m());
    for (JointInput& in : inputs) in.torque = constant_torque(0.3);
    EquationsOfMotion eq(model, inputs, ForceTerms{});
    VecX qu, vu;
    eq.initial_state(qu, vu);
    const int u = eq.unknowns();
    const double hg = 2e-3;
    const VecX Qk = qu + 1e-3 * VecX::LinSpaced(u, -1.0, 1.0), Vk = 0.1 * VecX::LinSpaced(u, 1.0, -0.5);
    const VecX A = VecX::LinSpaced(u, 2.0, -1.0), Q = Qk + hg * hg * A, V = Vk + hg * A;
    VecX direct(u), staged(u);
    eq.residual(0.1, Q.data(), V.data(), A.data(), direct.data());
    eq.begin_stage(Qk.data(), Vk.data(), hg);
    eq.stage_residual(0.1, Q.data(), V.data(), A.data(), staged.data());
    if (modes == 0) {
      EXPECT_EQ(direct, staged);
    } else {
      ASSERT_GT(u, model->m());
      EXPECT_LT((staged - direct).norm(), 1e-12 * direct.norm()) << (staged - direct).norm() / direct.norm();
      // (the residual of another stage's states is not the same: what the bound above watches)
      VecX other(u);
      eq.begin_stage(Qk.data(), Vk.data(), 2 * hg);
      eq.stage_residual(0.1, Q.data(), V.data(), A.data(), other.data());
      EXPECT_GT((other - direct).norm(), 1e-5 * direct.norm()) << (other - direct).norm() / direct.norm();
    }
  }
}
