// Finite-difference checks of every kernel's derivatives (docs/formulation.md §7 invariants 1 and 2):
// M against the kinetic energy, the inertial force against Lagrange's equations, sde and gravity
// forces against their energies, stiffness and damping matrices against the forces.
// Central differences with step h have truncation error ~h²·|f'''| and round-off ~ε|f|/h; with
// h = 1e-5 both are below 1e-8 relative, so 1e-6 relative to the matrix norm is a safe bound that
// any wrong term (of relative size ≥ 1e-4 in these random states) would exceed.
#include <gtest/gtest.h>

#include <functional>

#include "../assembly/assemble.hpp"
#include "../assembly/dense_reference.hpp"
#include "../core/positions.hpp"
#include "../core/rotation.hpp"
#include "../solvers/statics.hpp"
#include "../studies/linear_jacobian.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

constexpr double h = 1e-5;

// Jacobian of a vector function by central differences.
MatX fd_jacobian(const std::function<VecX(const VecX&)>& f, const VecX& x, double step = h) {
  const VecX f0 = f(x);
  MatX J(f0.size(), x.size());
  for (int i = 0; i < x.size(); ++i) {
    VecX xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    J.col(i) = (f(xp) - f(xm)) / (2 * step);
  }
  return J;
}

VecX fd_gradient(const std::function<double(const VecX&)>& f, const VecX& x, double step = h) {
  VecX g(x.size());
  for (int i = 0; i < x.size(); ++i) {
    VecX xp = x, xm = x;
    xp[i] += step;
    xm[i] -= step;
    g[i] = (f(xp) - f(xm)) / (2 * step);
  }
  return g;
}

double rel(const MatX& A, const MatX& B) { return (A - B).norm() / std::max(B.norm(), 1e-300); }

ForceTerms only(bool inertia, bool gravity, bool sde) {
  ForceTerms t;
  t.inertia = inertia;
  t.gravity = gravity;
  t.sde = sde;
  return t;
}

MatX assembled(const Model& m, const VecX& q, const VecX& v, const MatrixTerms& t) {
  std::vector<int> cols(m.m());
  for (int j = 0; j < m.m(); ++j) cols[j] = m.joint_index(j);
  const BorderedPattern p(m, cols);
  std::vector<double> vals;
  assemble_matrix(m, p, cols, q, v, t, vals);
  return to_dense(p, vals);
}

// M (sparse and dense) against the Hessian of T in q̇: T is quadratic in q̇, ∂T/∂q̇ = M q̇, so the
// Jacobian of the FD gradient is M. Returns the assembled M.
MatX expect_mass_is_hessian_of_kinetic_energy(const Model& m, const VecX& q, const VecX& v) {
  MatrixTerms t;
  t.mass = 1.0;
  const MatX M = assembled(m, q, v, t);
  auto grad = [&](const VecX& vv) {
    return fd_gradient([&](const VecX& x) { return energies(m, q, x).kinetic; }, vv, 1e-3);
  };
  const MatX Mfd = fd_jacobian(grad, v, 1e-3);
  EXPECT_LT(rel(M, Mfd), 1e-6);
  EXPECT_LT(rel(dense_mass_matrix(m, q), Mfd), 1e-6);
  return M;
}

// C (sparse and dense) against the Jacobian of the dissipative forces in q̇, and the dissipated
// power against q̇ · f_d.
void expect_damping_is_jacobian_of_dissipative_forces(const Model& m, const VecX& q, const VecX& v) {
  const VecX zero = VecX::Zero(m.dof());
  MatrixTerms t;
  t.damping = 1.0;
  auto fd = [&](const VecX& x) {
    VecX f;
    generalised_forces(m, q, x, zero, only(false, false, true), f);
    return f;
  };
  const MatX Cfd = fd_jacobian(fd, v);
  EXPECT_LT(rel(assembled(m, q, v, t), Cfd), 1e-6);
  EXPECT_LT(rel(dense_damping(m, q, v), Cfd), 1e-6);
  VecX f0;
  generalised_forces(m, q, zero, zero, only(false, false, true), f0);
  const double P = v.dot(fd(v) - f0);
  EXPECT_NEAR(energies(m, q, v).dissipation_rate, P, 1e-9 * std::abs(P));
}

// The inertial force against Lagrange's equations: d/dt (M(q(t)) v(t)) along
// q(t) = q + v t + a t²/2, minus ∂T/∂q.
void expect_inertial_force_satisfies_lagrange(const Model& m, const VecX& q, const VecX& v, const VecX& a) {
  VecX eps;
  generalised_forces(m, q, v, a, only(true, false, false), eps);
  MatrixTerms t;
  t.mass = 1.0;
  auto momentum = [&](double s) {
    const VecX qs = q + v * s + 0.5 * a * s * s, vs = v + a * s;
    return VecX(assembled(m, qs, vs, t) * vs);
  };
  const double dt = 1e-5;
  const VecX dpdt = (momentum(dt) - momentum(-dt)) / (2 * dt);
  const VecX dTdq = fd_gradient([&](const VecX& x) { return energies(m, x, v).kinetic; }, q);
  EXPECT_LT(rel(eps, dpdt - dTdq), 1e-6);
}

// Elastic and gravity forces are the gradients of their energies.
void expect_forces_are_gradients_of_energies(const Model& m, const VecX& q) {
  const VecX zero = VecX::Zero(m.dof());
  VecX fe, fg;
  generalised_forces(m, q, zero, zero, only(false, false, true), fe);
  generalised_forces(m, q, zero, zero, only(false, true, false), fg);
  EXPECT_LT(rel(fe, fd_gradient([&](const VecX& x) { return energies(m, x, zero).elastic; }, q)), 1e-6);
  EXPECT_LT(rel(fg, fd_gradient([&](const VecX& x) { return energies(m, x, zero).gravity; }, q)), 1e-6);
}

// K (sparse and dense, with the geometric and gravity terms) against the Jacobian of the elastic
// and gravity forces.
void expect_stiffness_is_jacobian_of_forces(const Model& m, const VecX& q) {
  const VecX zero = VecX::Zero(m.dof());
  MatrixTerms t;
  t.stiffness = 1.0;
  t.gravity = true;
  const MatX Kfd = fd_jacobian(
      [&](const VecX& x) {
        VecX f;
        generalised_forces(m, x, zero, zero, only(false, true, true), f);
        return f;
      },
      q);
  EXPECT_LT(rel(assembled(m, q, zero, t), Kfd), 1e-6);
  EXPECT_LT(rel(dense_stiffness(m, q, true), Kfd), 1e-6);
}

}  // namespace

// D(q) is [Ry(φ2) Rz(φ3) Rx(φ1), x; 0 1] (docs/formulation.md), its first derivatives are central
// differences of D and its second derivatives central differences of ∂R/∂φ, at angles up to 1 rad
// (the closed forms share no code with rot_x/y/z). With h = 1e-5 the differences' errors are ~1e-10;
// closed form against the product of three rotations: a few ulps per entry (more with FMA), so 1e-14.
TEST(KernelsFD, DeformationTransformAndItsDerivatives) {
  for (int trial = 0; trial < 20; ++trial) {
    const Vec6 q = Vec6::Random();
    DeformationTransform d;
    deformation_transform(q, d, true);
    const Mat3 R = rot_y(q[4]) * rot_z(q[5]) * rot_x(q[3]);
    EXPECT_LT((d.D.topLeftCorner<3, 3>() - R).norm(), 1e-14);
    EXPECT_TRUE((d.D.topRightCorner<3, 1>() == q.head<3>()));
    EXPECT_TRUE((d.D.row(3) == Eigen::RowVector4d(0, 0, 0, 1)));
    for (int j = 0; j < 6; ++j) {
      Vec6 qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      DeformationTransform dp, dm;
      deformation_transform(qp, dp, true);
      deformation_transform(qm, dm, true);
      const Mat34 fd = (dp.D - dm.D).topRows<3>() / (2 * h);
      EXPECT_LT((d.dD[j] - fd).norm(), 1e-9) << "dD/dq" << j;
      if (j < 3) continue;
      const int a = j - 3;
      EXPECT_TRUE((d.dD[j].leftCols<3>() == d.dR[a]));
      Mat3 gR;  // ∂R/∂φ_a = [g_a×] R
      for (int c = 0; c < 3; ++c) gR.col(c) = d.axis[a].cross(R.col(c));
      EXPECT_LT((d.dR[a] - gR).norm(), 1e-14);
      for (int b = 0; b < 3; ++b)
        EXPECT_LT((d.ddR[b][a] - (dp.dR[b] - dm.dR[b]) / (2 * h)).norm(), 1e-9) << "d2R/dphi" << b << "dphi" << a;
    }
  }
}

TEST(KernelsFD, MassMatrixIsHessianOfKineticEnergy) {
  const Model m = test::spatial_arm(4);
  VecX q, v, a;
  test::random_state(m, 1, q, v, a);
  const MatX M = expect_mass_is_hessian_of_kinetic_energy(m, q, v);
  EXPECT_LT(rel(M, M.transpose()), 1e-15);
  Eigen::SelfAdjointEigenSolver<MatX> es(M);
  EXPECT_GT(es.eigenvalues().minCoeff(), 0.0) << "M must be positive definite";
}

TEST(KernelsFD, InertialForceSatisfiesLagrangeEquations) {
  const Model m = test::spatial_arm(3);
  VecX q, v, a;
  test::random_state(m, 2, q, v, a);
  expect_inertial_force_satisfies_lagrange(m, q, v, a);
}

TEST(KernelsFD, JointsAboutAnyAxisAndAFreeBaseAreConsistent) {
  // The paper's arm on a free bus (case space_deployment): translations along x and y, rotations
  // about y and x of their joint frames, a bus body of its own. The same checks as for Craig's
  // z-axis joints hold.
  const Model m = build_model(read_case(test::source_path("cases/space_deployment.toml")), 3);
  VecX q, v, a;
  test::random_state(m, 12, q, v, a);
  expect_mass_is_hessian_of_kinetic_energy(m, q, v);
  expect_inertial_force_satisfies_lagrange(m, q, v, a);
}

TEST(KernelsFD, ForcesAreGradientsOfEnergies) {
  const Model m = test::spatial_arm(5);
  VecX q, v, a;
  test::random_state(m, 3, q, v, a);
  expect_forces_are_gradients_of_energies(m, q);
}

TEST(KernelsFD, StiffnessIsJacobianOfElasticAndGravityForces) {
  const Model m = test::spatial_arm(4);
  VecX q, v, a;
  test::random_state(m, 4, q, v, a);
  expect_stiffness_is_jacobian_of_forces(m, q);
}

TEST(KernelsFD, DampingMatrixIsJacobianOfDampingForces) {
  // The sde damping is a Rayleigh function of degree 2 in the rates.
  const Model m = test::spatial_arm(4, 0.01);
  VecX q, v, a;
  test::random_state(m, 5, q, v, a);
  expect_damping_is_jacobian_of_dissipative_forces(m, q, v);
}

TEST(KernelsFD, JointDrivesAreConsistent) {
  // Rotor inertia, viscous damping and tanh-smoothed Coulomb friction on every joint:
  // M is still the Hessian of the kinetic energy (with ½ J q̇²), C the Jacobian of the dissipative
  // forces (friction's slope F_c/v_s sech² included), the dissipated power q̇ · f_d, and the drive's
  // generalised force J q̈ + c q̇ + F_c tanh(q̇/v_s) lands in the joint's row only. v_s = 0.3 rad/s
  // keeps tanh smooth on the FD step (h/v_s ~ 3e-5), so the 1e-6 bound above still holds.
  Model m = test::spatial_arm(3, 0.01);
  for (auto& j : m.joints) j.drive = {0.25, 0.6, 0.4, 0.3};
  const Model bare = test::spatial_arm(3, 0.01);
  VecX q, v, a;
  test::random_state(m, 8, q, v, a);
  expect_mass_is_hessian_of_kinetic_energy(m, q, v);
  expect_damping_is_jacobian_of_dissipative_forces(m, q, v);
  VecX F, Fb;
  double P = 0.0, Pb = 0.0;
  generalised_forces(m, q, v, a, ForceTerms{}, F, &P);
  generalised_forces(bare, q, v, a, ForceTerms{}, Fb, &Pb);
  VecX expect = Fb;
  for (int j = 0; j < m.m(); ++j) {
    const double vj = v[m.joint_index(j)], aj = a[m.joint_index(j)];
    expect[m.joint_index(j)] += 0.25 * aj + 0.6 * vj + 0.4 * std::tanh(vj / 0.3);
    Pb += vj * (0.6 * vj + 0.4 * std::tanh(vj / 0.3));
  }
  EXPECT_LT((F - expect).norm(), 1e-12 * Fb.norm());
  EXPECT_NEAR(P, Pb, 1e-12 * Pb);
}

TEST(KernelsFD, CentrifugalStiffnessIsJacobianOfInertialForce) {
  const Model m = test::spatial_arm(3);
  VecX q, v, a;
  test::random_state(m, 6, q, v, a);
  v.head(m.flexible_dofs()).setZero();  // the steady-rotation state: rfes at rest in {r}
  const VecX zero = VecX::Zero(m.dof());
  MatrixTerms t;
  t.stiffness = 1.0;
  t.inertial = true;
  const BorderedPattern p(m.n(), 0);
  std::vector<double> vals;
  assemble_matrix(m, p, std::vector<int>(m.m(), -1), q, v, t, vals);
  const MatX Kc = to_dense(p, vals);
  t.inertial = false;
  assemble_matrix(m, p, std::vector<int>(m.m(), -1), q, v, t, vals);
  const MatX Kinertial = Kc - to_dense(p, vals);
  const int Nf = m.flexible_dofs();
  const MatX Kfd = fd_jacobian(
      [&](const VecX& x) {
        VecX qq = q;
        qq.head(Nf) = x;
        VecX f;
        generalised_forces(m, qq, v, zero, only(true, false, false), f);
        return VecX(f.head(Nf));
      },
      q.head(Nf));
  // Only rfe-diagonal blocks exist in the kernel; compare the symmetric part of those blocks.
  MatX Kfd_blocks = MatX::Zero(Nf, Nf);
  for (int k = 0; k < m.n(); ++k) {
    const Mat6 b = Kfd.block<6, 6>(6 * k, 6 * k);
    Kfd_blocks.block<6, 6>(6 * k, 6 * k) = 0.5 * (b + b.transpose());
  }
  EXPECT_LT(rel(Kinertial, Kfd_blocks), 1e-6);
}

TEST(KernelsFD, TipForceDoesVirtualWork) {
  const Model m = test::spatial_arm(3);
  VecX q, v, a;
  test::random_state(m, 7, q, v, a);
  TipLoads loads;
  loads.force = Vec3(1.0, -2.0, 3.0);
  const int n = m.n();
  const Vec6 Q = tip_generalised_force(m, 0, q.segment<6>(m.rfe_index(0, n - 1)), loads);
  // Q_j = F · ∂p_tip/∂q_j
  const VecX g = fd_gradient(
      [&](const VecX& x) {
        VecX qq = q;
        qq.segment<6>(m.rfe_index(0, n - 1)) = x;
        return loads.force.dot(tip_motion(m, 0, qq).head<3>());
      },
      VecX(q.segment<6>(m.rfe_index(0, n - 1))));
  EXPECT_LT((Q - g).norm(), 1e-8 * Q.norm());
}

TEST(KernelsFD, TreeOfLinksJointsAndPayloadsIsConsistent) {
  // Every kind of mounting at once (test::tree_arm: a joint on a link's tip, a wrist with an end
  // effector, a slider mid-link, a link fixed to another, payloads, gravity, damping): bodies beyond
  // an rfe move with its six coordinates, so every invariant above must hold for the whole tree.
  const Model m = test::tree_arm(2, 0.01);
  ASSERT_EQ(m.carrying, 4);
  VecX q, v, a;
  test::random_state(m, 21, q, v, a);
  const MatX M = expect_mass_is_hessian_of_kinetic_energy(m, q, v);
  Eigen::SelfAdjointEigenSolver<MatX> es(M);
  EXPECT_GT(es.eigenvalues().minCoeff(), 0.0) << "M must be positive definite";
  expect_inertial_force_satisfies_lagrange(m, q, v, a);
  expect_damping_is_jacobian_of_dissipative_forces(m, q, v);
  expect_forces_are_gradients_of_energies(m, q);
  expect_stiffness_is_jacobian_of_forces(m, q);
}

TEST(KernelsFD, PointMotionIsTheTimeDerivativeOfThePointsPosition) {
  // Along the curve q(s) = q + s v + s² a / 2 the point's position has derivative ṗ at s = 0 and
  // second derivative p̈; the body's rotation R has Ṙ = [ω×] R. Checked on the tree of every kind
  // of mounting (joints on links, a branch, a prismatic joint on a link), for points on rfe_0's span
  // (rigid with {r}), inside rfes and at the tip. Central differences of p with h = 1e-5 (ṗ, ω) and
  // h = 1e-3 (p̈: truncation ~h²|p''''| ~1e-6, round-off ~ε|p|/h² ~1e-10) against 1e-6 and 1e-4
  // of the values' scale: without the Coriolis term 2 Ḃ0 ṗ_r, p̈ is off by ~15 % here.
  const Model m = test::tree_arm(3, 0.0);
  VecX q, v, a;
  test::random_state(m, 11, q, v, a);
  for (int l = 0; l < static_cast<int>(m.links.size()); ++l) {
    const double L = m.links[l].d.length;
    for (double s : {0.0, 0.3 * L, 0.77 * L, L}) {
      const PointMotion pm = point_motion(m, l, s, q, v, a);
      auto at = [&](double e) {
        const VecX qe = q + e * v + 0.5 * e * e * a;
        std::vector<Vec3> p, d;
        std::vector<Mat3> R;
        axis_points(m, l, {s}, qe, p, d, &R);
        return std::make_pair(p[0], R[0]);
      };
      const auto [p0, R0] = at(0.0);
      EXPECT_LT((pm.position - p0).norm(), 1e-14 * (1.0 + p0.norm()));
      EXPECT_LT((pm.rotation - R0).norm(), 1e-14);
      const double hv = 1e-5, ha = 1e-3;
      const Vec3 vel = (at(hv).first - at(-hv).first) / (2 * hv);
      const Vec3 acc = (at(ha).first - 2.0 * p0 + at(-ha).first) / (ha * ha);
      const Mat3 W = (at(hv).second - at(-hv).second) / (2 * hv) * R0.transpose();
      const Vec3 w(W(2, 1), W(0, 2), W(1, 0));
      EXPECT_LT((pm.velocity - vel).norm(), 1e-6 * (1.0 + vel.norm())) << "link " << l << " s " << s;
      EXPECT_LT((pm.acceleration - acc).norm(), 1e-4 * (1.0 + acc.norm())) << "link " << l << " s " << s;
      EXPECT_LT((pm.angular_velocity - w).norm(), 1e-6 * (1.0 + w.norm())) << "link " << l << " s " << s;
    }
  }
}

// The linear models' sparse Jacobian (studies/linear_jacobian.hpp: rfes three apart differenced
// together, the nodes' rows split per rfe through its moments) against differencing the residual
// column by column, on the tree of every kind of mounting (4 carrying rfes, a prismatic joint, a
// branch, gravity, sde damping) at a random state, two joints prescribed and two under PD laws:
// the same differences of the same residual summed in other chunks, so equal to the differences'
// round-off (~1e-16 of a term over h = 1e-5, relative to the largest entry: 1e-11; 1e-9 allowed),
// the joints' torques (required, or the PD laws') alike.
TEST(LinearJacobian, EqualsTheColumnByColumnDifferencesOnATree) {
  const Model model = test::tree_arm(2, 0.01);
  VecX q, v, a;
  test::random_state(model, 7, q, v, a);
  std::vector<JointInput> in(static_cast<size_t>(model.m()));
  for (int j = 0; j < model.m(); ++j) {
    const double q0 = q[model.joint_index(j)];
    if (j % 2 == 0) {
      in[static_cast<size_t>(j)].motion = constant_rate_law(q0, 0.3);
    } else {
      in[static_cast<size_t>(j)].torque = pd_law(constant_rate_law(q0 + 0.01, 0.1), 40.0, 3.0, nullptr);
      in[static_cast<size_t>(j)].q0 = q0;
    }
  }
  const double t = 0.2;
  const EquationsJacobian J = equations_jacobian(model, in, ForceTerms{}, t, q, v, a);
  std::vector<int> ucoord;
  for (int i = 0; i < model.flexible_dofs(); ++i) ucoord.push_back(i);
  for (int j = 0; j < model.m(); ++j)
    if (j % 2 == 1) ucoord.push_back(model.joint_index(j));
  const int U = static_cast<int>(ucoord.size());
  ASSERT_EQ(J.K.rows(), U);
  auto residual = [&](const VecX& qq, const VecX& vv, const VecX& aa, VecX& r, VecX& tau) {
    VecX F;
    generalised_forces(model, qq, vv, aa, ForceTerms{}, F);
    tau.resize(model.m());
    for (int j = 0; j < model.m(); ++j) {
      const int c = model.joint_index(j);
      tau[j] = in[static_cast<size_t>(j)].prescribed() ? F[c] : in[static_cast<size_t>(j)].torque->at(t, qq[c], vv[c]);
    }
    r.resize(U);
    for (int i = 0; i < U; ++i) r[i] = F[ucoord[static_cast<size_t>(i)]];
    for (int j = 0, i = model.flexible_dofs(); j < model.m(); ++j)
      if (j % 2 == 1) r[i++] -= tau[j];
  };
  const double h = kLinearizationStep;
  const SparseMat* mats[3] = {&J.K, &J.D, &J.M};
  const MatX* taus[3] = {&J.tau_q, &J.tau_v, &J.tau_a};
  for (int kind = 0; kind < 3; ++kind) {
    const MatX Js(*mats[kind]);
    const double scale = Js.cwiseAbs().maxCoeff(), tscale = taus[kind]->cwiseAbs().maxCoeff();
    double worst = 0.0, tworst = 0.0;
    for (int c = 0; c < U; ++c) {
      VecX x[3] = {q, v, a}, r1, r2, r3, r4, t1, t2, t3, t4;
      const int k = ucoord[static_cast<size_t>(c)];
      auto at = [&](double d, VecX& r, VecX& tau) {
        VecX y[3] = {q, v, a};
        y[kind][k] += d;
        residual(y[0], y[1], y[2], r, tau);
      };
      VecX col, tcol;
      if (kind < 2) {
        at(h, r1, t1), at(-h, r2, t2), at(2 * h, r3, t3), at(-2 * h, r4, t4);
        col = (8 * (r1 - r2) - (r3 - r4)) / (12 * h);
        tcol = (8 * (t1 - t2) - (t3 - t4)) / (12 * h);
      } else {
        at(1.0, r1, t1), at(0.0, r2, t2);
        col = r1 - r2;
        tcol = t1 - t2;
      }
      worst = std::max(worst, (Js.col(c) - col).cwiseAbs().maxCoeff());
      tworst = std::max(tworst, (taus[kind]->col(c) - tcol).cwiseAbs().maxCoeff());
    }
    EXPECT_GT(scale, 0.0) << kind;
    EXPECT_LE(worst, 1e-9 * scale) << "matrix " << kind << " (K, D, M)";
    EXPECT_LE(tworst, 1e-9 * std::max(tscale, 1e-300)) << "torques " << kind;
  }
}
