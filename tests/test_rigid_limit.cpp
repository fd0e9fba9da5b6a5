// The rigid manipulator is the case n = 0 (docs/formulation.md §7 invariant 8): inverse dynamics of one-
// and two-link arms against closed-form torques, and a flexible link held undeformed acts on the
// base exactly as the rigid body made of all its rfes.
#include <gtest/gtest.h>

#include <cmath>

#include "../assembly/assemble.hpp"
#include "../core/rotation.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {
constexpr double g = 9.81;

Joint arm_joint(double a, double mass, double lc, double Izz) {
  Joint j;
  j.a = a;
  j.H = pseudo_inertia(mass, Vec3(lc, 0, 0), Vec3(0.01, Izz, Izz).asDiagonal());
  return j;
}

VecX torques(const Model& m, const VecX& q, const VecX& v, const VecX& a) {
  VecX F;
  generalised_forces(m, q, v, a, ForceTerms{}, F);
  return F;
}
}  // namespace

TEST(RigidLimit, OneLinkArmInVerticalPlane) {
  Joint j = arm_joint(0.0, 2.0, 0.4, 0.05);
  j.alpha = M_PI / 2;  // z1 horizontal: the arm swings in the vertical x–z plane
  const Model m = make_model({j}, Mat4::Identity(), Discretisation{}, g);
  for (double q : {-0.7, 0.0, 1.2}) {
    const VecX Q = VecX::Constant(1, q), V = VecX::Constant(1, 1.5), A = VecX::Constant(1, -2.0);
    const double expected = (0.05 + 2.0 * 0.4 * 0.4) * A[0] + 2.0 * g * 0.4 * std::cos(q);
    EXPECT_NEAR(torques(m, Q, V, A)[0], expected, 1e-12 * std::abs(expected) + 1e-12);
  }
}

TEST(RigidLimit, TwoLinkArmClosedForm) {
  const double m1 = 2.0, m2 = 1.5, L1 = 0.8, lc1 = 0.35, lc2 = 0.3, I1 = 0.06, I2 = 0.04;
  Joint j1 = arm_joint(0.0, m1, lc1, I1), j2 = arm_joint(L1, m2, lc2, I2);
  j1.alpha = M_PI / 2;
  const Model m = make_model({j1, j2}, Mat4::Identity(), Discretisation{}, g);
  const VecX q = Eigen::Vector2d(0.3, -1.1), v = Eigen::Vector2d(0.7, -1.3), a = Eigen::Vector2d(1.9, 0.4);
  const double c2 = std::cos(q[1]), s2 = std::sin(q[1]), c1 = std::cos(q[0]), c12 = std::cos(q[0] + q[1]);
  const double M11 = I1 + I2 + m1 * lc1 * lc1 + m2 * (L1 * L1 + lc2 * lc2 + 2 * L1 * lc2 * c2);
  const double M12 = I2 + m2 * (lc2 * lc2 + L1 * lc2 * c2), M22 = I2 + m2 * lc2 * lc2;
  const double h1 = -m2 * L1 * lc2 * s2 * (2 * v[0] * v[1] + v[1] * v[1]), h2 = m2 * L1 * lc2 * s2 * v[0] * v[0];
  const double g1 = (m1 * lc1 + m2 * L1) * g * c1 + m2 * lc2 * g * c12, g2 = m2 * lc2 * g * c12;
  const VecX tau = torques(m, q, v, a);
  EXPECT_NEAR(tau[0], M11 * a[0] + M12 * a[1] + h1 + g1, 1e-12 * 50);
  EXPECT_NEAR(tau[1], M12 * a[0] + M22 * a[1] + h2 + g2, 1e-12 * 50);
}

TEST(RigidLimit, UndeformedFlexibleLinkActsAsRigidBody) {
  const Model flex = test::spatial_arm(12);
  const Model rigid = rigidify(flex);  // every rfe's pseudo-inertia moved into the last link
  VecX q, v, a;
  test::random_state(flex, 21, q, v, a);
  const int Nf = flex.flexible_dofs();
  q.head(Nf).setZero();
  v.head(Nf).setZero();
  a.head(Nf).setZero();
  const VecX tf = torques(flex, q, v, a).tail(flex.m());
  const VecX tr = torques(rigid, q.tail(2), v.tail(2), a.tail(2));
  EXPECT_LT((tf - tr).norm(), 1e-12 * tr.norm());
}
