// Cantilever convergence (docs/formulation.md §7 invariants 5 and 6): bending frequencies in both
// planes, axial and torsional frequencies, static tip deflection and rotation converge to exact
// beam theory with observed order ≈ 2. Kane's beam, with Iz raised to 3e-7 m⁴ so that the two
// bending planes are distinct.
//
// RFEM converges to a beam with shear flexibility and rotary inertia (Timoshenko), so the
// Richardson-extrapolated frequency differs from Euler–Bernoulli by at most
// (βL)²(r/L)²(1 + E/κG) (r² = I/A): that is the tolerance for the extrapolated values.
#include <gtest/gtest.h>

#include <cmath>

#include "../studies/quantities.hpp"
#include "../solvers/beam_theory.hpp"
#include "../solvers/modes.hpp"
#include "../solvers/refinement.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

Case kane() { return read_case(test::source_path("cases/kane_beam.toml"), {"sections.kane.Iz=3e-7"}); }

struct Series {
  std::vector<double> v;
  double order() const { return std::log2(std::abs((v[1] - v[0]) / (v[2] - v[1]))); }  // n doubles
  double richardson() const { return v[2] + (v[2] - v[1]) / (std::pow(2.0, order()) - 1.0); }
};

Series series(const Case& c, const std::string& q, std::vector<int> ns = {20, 40, 80}) {
  Series s;
  for (int n : ns) s.v.push_back(evaluate_quantity(c, n, q));
  return s;
}

double timoshenko_bound(const Segment& s, double beta_l, double I) {
  const double r2 = I / s.section.A;
  return beta_l * beta_l * r2 / (s.length * s.length) * (1.0 + s.material.E / (s.section.kappa_y * s.material.G));
}

}  // namespace

TEST(Cantilever, BendingFrequenciesConvergeWithOrderTwoInBothPlanes) {
  const Case c = kane();
  const Segment& seg = c.links[0].link.segments[0];
  for (const auto& [kind, name, I] : {std::tuple{ModeKind::BendingY, "bending-y", seg.section.Iz},
                                      std::tuple{ModeKind::BendingZ, "bending-z", seg.section.Iy}}) {
    for (int k = 1; k <= 3; ++k) {
      const Series s = series(c, std::string(name) + ":" + std::to_string(k));
      const double exact = beam::cantilever_omega(seg, kind, k) / (2 * M_PI);
      EXPECT_NEAR(s.order(), 2.0, 0.15) << name << k;
      EXPECT_LT(std::abs(s.richardson() / exact - 1.0), timoshenko_bound(seg, beam::cantilever_beta_l(k), I))
          << name << k;
      const double tol_n40[3] = {1e-3, 3e-3, 5e-3};  // the acceptance figures
      EXPECT_LT(std::abs(s.v[1] / exact - 1.0), tol_n40[k - 1]) << name << k << " at n = 40";
    }
  }
  EXPECT_NEAR(beam::cantilever_beta_l(1), 1.875104, 1e-6);
  EXPECT_NEAR(beam::cantilever_beta_l(2), 4.694091, 1e-6);
  EXPECT_NEAR(beam::cantilever_beta_l(3), 7.854757, 1e-6);
}

TEST(Cantilever, TipPayloadMatchesTheTipMassFrequencyEquation) {
  // cases/kane_tip_mass.toml: a 6 kg end effector (μ = M/ρAL = 0.5) with 1.2 kg m²
  // about its centre on the tip (η = J/ρAL³ = 1e-3), Iz raised as above. Its bending frequencies
  // converge with order 2 to the Euler–Bernoulli cantilever with tip mass and rotary inertia, up to
  // the same Timoshenko bound as the free cantilever's (the payload adds no shear of its own).
  // Without the payload, or with it on the wrong rfe, mode 1 would be 40 % higher.
  const Case c = read_case(test::source_path("cases/kane_tip_mass.toml"), {"sections.kane.Iz=3e-7"});
  const Segment& seg = c.links[0].link.segments[0];
  const double rhoA = seg.material.rho * seg.section.A, L = seg.length, mu = 6.0 / (rhoA * L), eta = 1.2 / (rhoA * L * L * L);
  ASSERT_EQ(c.links[0].link.payloads.size(), 1u);
  for (const auto& [name, I] : {std::pair{"bending-y", seg.section.Iz}, std::pair{"bending-z", seg.section.Iy}}) {
    for (int k = 1; k <= 2; ++k) {
      const Series s = series(c, std::string(name) + ":" + std::to_string(k));
      const double lam = beam::cantilever_tip_mass_beta_l(mu, eta, k);
      const double exact = lam * lam / (L * L) * std::sqrt(seg.material.E * I / rhoA) / (2 * M_PI);
      char rel[32];
      std::snprintf(rel, sizeof rel, "%.2e", s.richardson() / exact - 1.0);
      RecordProperty(std::string(name) + std::to_string(k) + "_richardson_error", rel);
      EXPECT_NEAR(s.order(), 2.0, 0.15) << name << k;
      EXPECT_LT(std::abs(s.richardson() / exact - 1.0), timoshenko_bound(seg, lam, I)) << name << k;
    }
  }
  // The frequency equation's limits: no payload is the free cantilever; a huge mass pins the tip for
  // every mode but the first: the mass on the beam's spring 3EI/L³, λ → (3/μ)^¼.
  EXPECT_NEAR(beam::cantilever_tip_mass_beta_l(0.0, 0.0, 2), beam::cantilever_beta_l(2), 1e-12);
  EXPECT_NEAR(beam::cantilever_tip_mass_beta_l(1.0, 0.0, 1), 1.247917, 1e-6);  // M = beam mass (tables)
  EXPECT_NEAR(beam::cantilever_tip_mass_beta_l(1e9, 0.0, 2), 3.926602, 1e-5);  // clamped–pinned
  EXPECT_NEAR(beam::cantilever_tip_mass_beta_l(1e9, 0.0, 1), std::pow(3.0 / 1e9, 0.25), 1e-6);
}

TEST(Cantilever, AxialAndTorsionalFrequenciesConverge) {
  const Case c = kane();
  const Segment& seg = c.links[0].link.segments[0];
  for (const auto& [kind, name] : {std::pair{ModeKind::Axial, "axial"}, std::pair{ModeKind::Torsion, "torsion"}}) {
    for (int k = 1; k <= 2; ++k) {
      const Series s = series(c, std::string(name) + ":" + std::to_string(k));
      const double exact = beam::cantilever_omega(seg, kind, k) / (2 * M_PI);
      EXPECT_NEAR(s.order(), 2.0, 0.1) << name << k;
      // Rods have no shear/rotary correction: the extrapolation is limited by the O(n⁻⁴) term.
      EXPECT_LT(std::abs(s.richardson() / exact - 1.0), 1e-5) << name << k;
    }
  }
}

TEST(Cantilever, StaticTipDeflectionAndRotation) {
  const Case c = kane();  // 1 N tip force along −z: bending about y (Iy)
  const Segment& seg = c.links[0].link.segments[0];
  const double P = -1.0;
  const Series w = series(c, "tip:uz", {10, 20, 40});
  const Series r = series(c, "tip:ry", {10, 20, 40});
  EXPECT_NEAR(w.order(), 2.0, 0.1);
  // Geometric nonlinearity at this load changes the tip deflection by ~(w/L)² ≈ 6e-6 relative.
  EXPECT_NEAR(w.richardson(), beam::cantilever_tip_deflection(seg, P, true), 2e-5 * std::abs(w.v[2]));
  // The tip rotation of rfe_n (half an rfe from the tip) converges to PL²/2EI too; ry = −dw/dx.
  EXPECT_NEAR(r.richardson(), -beam::cantilever_tip_rotation(seg, P, true), 2e-5 * std::abs(r.v[2]));
}

TEST(Cantilever, LanczosMatchesDenseEigenSolver) {
  const Case c = kane();
  const Model m = build_model(c, 150);
  const VecX qb, vb;
  const ModesResult dense = compute_modes(m, qb, vb, m.flexible_dofs(), 100000);
  const ModesResult lanczos = compute_modes(m, qb, vb, 8, 0);
  ASSERT_FALSE(lanczos.dense);
  // The dense solver's eigenvalues carry an absolute error ~ε λ_max (axial modes make
  // λ_max/λ_1 ~ 1e9 here); shift-invert is accurate near σ = 0. Allow 100 ε (ω_max/ω_i)².
  const double wmax = dense.omega.maxCoeff();
  for (int i = 0; i < 8; ++i) {
    const double tol = 100 * 2.2e-16 * std::pow(wmax / dense.omega[i], 2);
    EXPECT_NEAR(lanczos.omega[i] / dense.omega[i], 1.0, tol) << "mode " << i + 1;
  }
}

TEST(RotatingBeam, SouthwellCoefficients) {
  // Kane's beam on a hub turning about z: ω² = ω₀² + K Ω². Flapwise (deflection along the rotation
  // axis) K₁ = 1.193 for a uniform cantilever with zero hub radius (Wright et al. 1982); in the
  // plane of rotation centrifugal softening subtracts exactly Ω², so K_lag = K_flap − 1.
  // Small Ω = 0.1 rad/s keeps the quadratic law exact to ~(Ω/ω₀)² = 1e-3 relative in K.
  const Case c = read_case(test::source_path("cases/kane_spinup.toml"), {"sections.kane.Iz=3e-7"});
  const Model m = build_model(c, 80);
  const VecX qb = VecX::Zero(1), v0 = VecX::Zero(1), v1 = VecX::Constant(1, 0.1);
  const ModesResult a = compute_modes(m, qb, v0, 2), b = compute_modes(m, qb, v1, 2);
  auto K = [&](ModeKind kind) {
    double w0 = 0, w1 = 0;
    for (int i = 0; i < 2; ++i) {
      if (a.kind[i] == kind) w0 = a.omega[i];
      if (b.kind[i] == kind) w1 = b.omega[i];
    }
    return (w1 * w1 - w0 * w0) / 0.01;
  };
  const double flap = K(ModeKind::BendingZ), lag = K(ModeKind::BendingY);
  EXPECT_NEAR(flap, 1.193, 0.005);
  EXPECT_NEAR(flap - lag, 1.0, 0.005);
}

TEST(Cantilever, ErrorAgainstTheTimoshenkoReferenceFallsAsOneOverNSquared) {
  // The reference `rfem modes` prints for bending: the Timoshenko cantilever (shear and rotary
  // inertia, which the rfes and sdes carry). The error against it keeps falling with order 2 for
  // the first three modes in both planes; against Euler–Bernoulli it would stall at the shear
  // correction (as the printed error once did, growing with n).
  const Case c = kane();
  const Segment& s = c.links[0].link.segments[0];
  for (const char* kind : {"bending-y", "bending-z"})
    for (int k = 1; k <= 3; ++k) {
      const std::string q = std::string(kind) + ":" + std::to_string(k);
      const double ref =
          beam::cantilever_omega_timoshenko(s, kind[8] == 'y' ? ModeKind::BendingY : ModeKind::BendingZ, k) / (2 * M_PI);
      const Series f = series(c, q);
      const double e1 = std::abs(f.v[1] - ref), e2 = std::abs(f.v[2] - ref);
      EXPECT_NEAR(std::log2(e1 / e2), 2.0, 0.3) << q << ": errors " << e1 << " → " << e2;
      // and the Timoshenko value lies below Euler–Bernoulli by the shear correction
      const double eb = beam::cantilever_omega(s, kind[8] == 'y' ? ModeKind::BendingY : ModeKind::BendingZ, k) / (2 * M_PI);
      EXPECT_LT(ref, eb) << q;
    }
}

TEST(RotatingBeam, StaticStretchOfASpinningBar) {
  // `rfem static --rate Ω` on Kane's beam turning about the vertical at its root: the axial tip
  // displacement of a bar under its own centrifugal load, E u'' + ρΩ²(x + u) = 0, u(0) = u'(L) = 0:
  // u(L) = tan(kL)/k − L with k = Ω √(ρ/E) (5.1e-4 m at Ω = 6 rad/s). Order-2 convergence in n.
  const Case c = read_case(test::source_path("cases/kane_spinup.toml"));
  const Segment& s = c.links[0].link.segments[0];
  const double Omega = 6.0, k = Omega * std::sqrt(s.material.rho / s.material.E), L = s.length;
  const double exact = std::tan(k * L) / k - L;
  std::vector<double> u;
  for (int n : {10, 20, 40}) {
    JointRate o;
    o.rate = Omega;
    o.given = true;
    const Model m = build_model(c, n);
    VecX qb, vb;
    joint_state(c, o, qb, vb);
    u.push_back(tip_motion(m, 0, solve_static(m, qb, vb, TipLoads{}).q)[0]);
  }
  const double p = std::log2(std::abs((u[1] - u[0]) / (u[2] - u[1])));
  const double rich = u[2] + (u[2] - u[1]) / (std::pow(2.0, p) - 1.0);
  RecordProperty("stretch_m", std::to_string(u[2]));
  EXPECT_NEAR(p, 2.0, 0.3);
  EXPECT_NEAR(rich, exact, 1e-4 * exact) << "n = 40: " << u[2];
}

TEST(FreeJoints, BeamOnAFreeHubHasThePinnedFreeFrequencies) {
  // Kane's beam on its hub (vertical axis through the root, no hub inertia) with the hub free:
  // one rigid mode at ω = 0; the horizontal-plane bending becomes pinned–free (tan βL = tanh βL)
  // and converges at least with order 2 to within the Timoshenko bound of it (measured: order
  // 3.5–3.7, the limit 1.6e-4 below Euler–Bernoulli — with no clamped end the 1/n² term of the
  // cantilever nearly vanishes); the vertical-plane bending does not couple to the hub and keeps
  // the cantilever's frequencies to the dense solver's round-off, 100 ε (ω_max/ω)².
  const Case c = read_case(test::source_path("cases/kane_spinup.toml"));
  const Segment& seg = c.links[0].link.segments[0];
  const double unit = std::sqrt(seg.material.E * seg.section.Iz / (seg.material.rho * seg.section.A)) / (seg.length * seg.length);
  std::vector<Series> pinned(3);
  for (int n : {20, 40, 80}) {
    const Model m = build_model(c, n);
    const VecX qb = c.joint_values, vb = c.joint_rates;
    const ModesResult held = compute_modes(m, qb, vb, m.flexible_dofs());
    const ModesResult free = compute_modes(m, qb, vb, 7, 600, {0});
    const double wmax = held.omega.maxCoeff();
    ASSERT_EQ(free.kind[0], ModeKind::Rigid);
    EXPECT_EQ(free.omega[0], 0.0);
    int ky = 0, kz = 0;
    for (int i = 1; i < 7; ++i) {
      if (free.kind[i] == ModeKind::BendingY && ky < 3) pinned[ky++].v.push_back(free.omega[i]);
      if (free.kind[i] == ModeKind::BendingZ) {
        int seen = 0;  // the held run's kz-th bending-z mode
        for (int j = 0; j < 6; ++j)
          if (held.kind[j] == ModeKind::BendingZ && seen++ == kz) {
            EXPECT_NEAR(free.omega[i] / held.omega[j], 1.0, 100 * 2.2e-16 * std::pow(wmax / held.omega[j], 2));
          }
        ++kz;
      }
    }
    ASSERT_EQ(ky, 3) << "n = " << n;
  }
  for (int k = 1; k <= 3; ++k) {
    const double exact = std::pow(beam::pinned_free_beta_l(k), 2) * unit;
    EXPECT_GT(pinned[k - 1].order(), 1.85) << "pinned-free mode " << k;
    RecordProperty("pinned_free_order_" + std::to_string(k), std::to_string(pinned[k - 1].order()));
    EXPECT_LT(std::abs(pinned[k - 1].richardson() / exact - 1.0), timoshenko_bound(seg, beam::pinned_free_beta_l(k), seg.section.Iz))
        << "pinned-free mode " << k;
  }
  EXPECT_NEAR(beam::pinned_free_beta_l(1), 3.926602, 1e-6);
  EXPECT_NEAR(beam::pinned_free_beta_l(2), 7.068583, 1e-6);
}

TEST(FreeJoints, BeamOnAWeightlessFreeBaseHasTheFreeFreeFrequencies) {
  // Kane's beam (Iz = 3e-7) on a free base whose bus weighs 1e-9 of the beam: six rigid modes,
  // then free–free bending in both planes (cos βL cosh βL = 1), at least order 2 (measured 3.5–3.6,
  // as the pinned–free beam's) with Richardson within the Timoshenko bound; Lanczos agrees with
  // the dense solver.
  const Case c = kane();
  const Segment& seg = c.links[0].link.segments[0];
  const double mass = seg.material.rho * seg.section.A * seg.length, tiny = 1e-9 * mass;
  Mat4 H = Mat4::Zero();
  H.diagonal() << tiny, tiny, tiny, tiny;  // a point-like bus of inertia ~ tiny · 1 m²
  std::vector<Series> y(2), z(2);
  for (int n : {20, 40, 80}) {
    Model m = build_model(c, n);
    std::vector<MountedLink> links = m.links;
    links[0].on = Mounting{};  // on the last joint: the bus
    m = make_model(free_base_joints(H), links, 0.0, true);
    const std::vector<int> all{0, 1, 2, 3, 4, 5};
    const VecX qb = VecX::Zero(6), vb = VecX::Zero(6);
    const ModesResult r = compute_modes(m, qb, vb, 12, 600, all);
    for (int i = 0; i < 6; ++i) ASSERT_EQ(r.kind[i], ModeKind::Rigid) << "mode " << i + 1 << " at n = " << n;
    int ky = 0, kz = 0;
    for (int i = 6; i < 12; ++i) {
      if (r.kind[i] == ModeKind::BendingY && ky < 2) y[ky++].v.push_back(r.omega[i]);
      if (r.kind[i] == ModeKind::BendingZ && kz < 2) z[kz++].v.push_back(r.omega[i]);
    }
    ASSERT_EQ(ky, 2);
    ASSERT_EQ(kz, 2);
    const ModesResult ax = compute_modes(m, qb, vb, 1, 0, all);  // Lanczos: lowest is rigid
    EXPECT_EQ(ax.kind[0], ModeKind::Rigid);
    if (n == 40) {
      const ModesResult lz = compute_modes(m, qb, vb, 12, 0, all);
      ASSERT_FALSE(lz.dense);
      // the dense solver's round-off, as in LanczosMatchesDenseEigenSolver: 100 ε (ω_max/ω)²
      const double wmax = compute_modes(m, qb, vb, m.flexible_dofs() + 6, 600, all).omega.maxCoeff();
      for (int i = 6; i < 12; ++i)
        EXPECT_NEAR(lz.omega[i] / r.omega[i], 1.0, 100 * 2.2e-16 * std::pow(wmax / r.omega[i], 2)) << "mode " << i + 1;
    }
  }
  for (int k = 1; k <= 2; ++k)
    for (const auto& [s, I] : {std::pair{y[k - 1], seg.section.Iz}, std::pair{z[k - 1], seg.section.Iy}}) {
      const double bl = beam::free_free_beta_l(k);
      const double exact = bl * bl / (seg.length * seg.length) * std::sqrt(seg.material.E * I / (seg.material.rho * seg.section.A));
      EXPECT_GT(s.order(), 1.85) << "free-free mode " << k << " I = " << I;
      EXPECT_LT(std::abs(s.richardson() / exact - 1.0), timoshenko_bound(seg, bl, I)) << "free-free mode " << k;
    }
  EXPECT_NEAR(beam::free_free_beta_l(1), 4.730041, 1e-6);
  EXPECT_NEAR(beam::free_free_beta_l(2), 7.853205, 1e-6);
}

// An error bar (solvers/refinement.hpp: Roache's GCI over the last two n) on the cantilever's
// values whose exact answers are known: the first three bending frequencies (the Timoshenko
// cantilever the rfes converge to) and the static tip deflection. (Not the tip rotation: its
// discretisation error is ~1e-11 at n = 10, below the geometric nonlinearity that the linear
// beam's formula leaves out, 1.7e-8: a model-form error, which no bar over n can show.) Each bar contains the
// exact value, and is honest: at most 5 times the true error (docs/accuracy.md; the GCI with
// Fs = 1.25 on an order-2 series is 1.25 times the Richardson estimate, which is near the true
// error in the asymptotic range), on three ladders.
TEST(Cantilever, ErrorBarsContainTheExactValuesAndAreHonest) {
  const Case c = kane();
  const Segment& seg = c.links[0].link.segments[0];
  std::vector<std::pair<std::string, double>> exact;
  for (int k = 1; k <= 3; ++k)
    exact.emplace_back("bending-y:" + std::to_string(k), beam::cantilever_omega_timoshenko(seg, ModeKind::BendingY, k) / (2 * M_PI));
  exact.emplace_back("tip:uz", beam::cantilever_tip_deflection(seg, -1.0, true));
  for (const std::vector<int>& ns : {std::vector<int>{5, 10, 20}, {10, 20, 40}, {20, 40, 80}})
    for (const auto& [q, value] : exact) {
      const Series s = series(c, q, ns);
      const Refinement r = assess_refinement(ns, s.v, 0.0);  // (no time integration)
      const double truth = std::abs(s.v.back() - value);
      ASSERT_TRUE(r.asymptotic) << q << " from n = " << ns[0];
      EXPECT_EQ(r.safety_factor, 1.25) << q;
      EXPECT_EQ(r.error_time, 0.0);
      EXPECT_GE(r.error, truth) << q << " from n = " << ns[0] << ": the bar does not contain the exact value";
      EXPECT_LE(r.error, 5.0 * truth) << q << " from n = " << ns[0] << ": the bar is padded";
    }
}

// The bar's formula and its refusals, on series of known error: v = 1 + n^-p exactly.
TEST(Refinement, TheBarIsTheGciAndNoneIsGivenOutsideTheAsymptoticRange) {
  const std::vector<int> ns = {8, 16, 32};
  auto ladder = [&](double p) {
    std::vector<double> v;
    for (int n : ns) v.push_back(1.0 + std::pow(double(n), -p));
    return v;
  };
  // Order 2: Fs = 1.25 and r^p − 1 = 3: the bar is 1.25 times the true error 32^-2, plus the time part.
  const Refinement two = assess_refinement(ns, ladder(2.0), 1e-6);
  ASSERT_TRUE(two.asymptotic);
  EXPECT_NEAR(two.error_space, 1.25 * std::pow(32.0, -2.0), 1e-12);
  EXPECT_NEAR(two.error, two.error_space + 1e-6, 1e-15);
  // Order 3 (better than the method has): Fs = 3 and the order taken as 2: a wider bar.
  const Refinement three = assess_refinement(ns, ladder(3.0), 0.0);
  ASSERT_TRUE(three.asymptotic);
  EXPECT_EQ(three.safety_factor, 3.0);
  EXPECT_NEAR(three.error_space, 3.0 * (std::pow(16.0, -3.0) - std::pow(32.0, -3.0)) / 3.0, 1e-12);
  // Order 0.8, an oscillating series, a time error as large as the last change, a dynamic value
  // without the check: no bar, or no time part.
  for (const Refinement& r : {assess_refinement(ns, ladder(0.8), 0.0), assess_refinement(ns, {1.0, 1.1, 1.05}, 0.0),
                              assess_refinement(ns, ladder(2.0), 1e-3)}) {
    EXPECT_FALSE(r.asymptotic);
    EXPECT_TRUE(std::isnan(r.error) && std::isnan(r.error_space));
    EXPECT_FALSE(r.warnings.empty());
  }
  const Refinement unchecked = assess_refinement(ns, ladder(2.0), NAN);
  EXPECT_TRUE(unchecked.asymptotic && std::isnan(unchecked.error_time));
  EXPECT_EQ(unchecked.error, unchecked.error_space);
}
