// The paper's stepped link 3 (B1 + B2) as a cantilever: RFEM bending frequencies, extrapolated,
// agree with an independent exact solution of the two-segment Euler–Bernoulli cantilever
// (transfer matrices of Krylov functions, roots of the 2×2 free-end determinant).
// B2's mass-centre offset is set to 0 here: the exact solution has no bending–torsion coupling.
#include <gtest/gtest.h>

#include <cmath>

#include "../studies/quantities.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

using Mat4d = Eigen::Matrix4d;

// Transfer matrix of [w, w', w'', w'''] over length x for w'''' = β⁴ w.
Mat4d transfer(double beta, double x) {
  const double bx = beta * x, ch = std::cosh(bx), sh = std::sinh(bx), c = std::cos(bx), s = std::sin(bx);
  const double K1 = 0.5 * (ch + c), K2 = 0.5 * (sh + s) / beta, K3 = 0.5 * (ch - c) / (beta * beta),
               K4 = 0.5 * (sh - s) / (beta * beta * beta), b4 = std::pow(beta, 4);
  Mat4d T;
  T << K1, K2, K3, K4, b4 * K4, K1, K2, K3, b4 * K3, b4 * K4, K1, K2, b4 * K2, b4 * K3, b4 * K4, K1;
  return T;
}

// Free-end determinant for circular frequency ω; bending stiffness EI_s and mass ρA_s per segment.
double determinant(const std::vector<Segment>& segs, bool along_z, double omega) {
  Mat4d T = Mat4d::Identity();
  for (size_t i = 0; i < segs.size(); ++i) {
    const Segment& s = segs[i];
    const double EI = s.material.E * (along_z ? s.section.Iy : s.section.Iz), rhoA = s.material.rho * s.section.A;
    const double beta = std::pow(omega * omega * rhoA / EI, 0.25);
    if (i > 0) {  // continuity of w, w', EI w'', EI w''' across the step
      const Segment& p = segs[i - 1];
      const double EIp = p.material.E * (along_z ? p.section.Iy : p.section.Iz);
      Mat4d J = Mat4d::Identity();
      J(2, 2) = J(3, 3) = EIp / EI;
      T = J * T;
    }
    T = transfer(beta, s.length) * T;
  }
  // Clamped start: w = w' = 0; unknown w'', w'''. Free end: w'' = w''' = 0.
  return T(2, 2) * T(3, 3) - T(2, 3) * T(3, 2);
}

std::vector<double> exact_frequencies(const std::vector<Segment>& segs, bool along_z, int count) {
  std::vector<double> out;
  double w0 = 0.1, f0 = determinant(segs, along_z, w0);
  for (double w = w0 * 1.001; out.size() < static_cast<size_t>(count); w *= 1.001) {
    const double f = determinant(segs, along_z, w);
    if ((f > 0) != (f0 > 0)) {
      double a = w0, b = w;
      for (int it = 0; it < 200; ++it) {
        const double c = 0.5 * (a + b);
        ((determinant(segs, along_z, c) > 0) == (determinant(segs, along_z, a) > 0) ? a : b) = c;
      }
      out.push_back(0.5 * (a + b) / (2 * M_PI));
    }
    w0 = w;
    f0 = f;
  }
  return out;
}

}  // namespace

TEST(SteppedLink, ExtrapolatedFrequenciesMatchExactTwoSegmentBeam) {
  const Case c = read_case(test::source_path("cases/paper_link3.toml"), {"sections.B2.offset_y=0.0"});
  for (const auto& [along_z, name] : {std::pair{true, "bending-z"}, std::pair{false, "bending-y"}}) {
    const auto exact = exact_frequencies(c.links[0].link.segments, along_z, 3);
    for (int k = 1; k <= 3; ++k) {
      std::vector<double> v;
      for (int n : {24, 48, 96}) v.push_back(evaluate_quantity(c, n, std::string(name) + ":" + std::to_string(k)));
      const double p = std::log2(std::abs((v[1] - v[0]) / (v[2] - v[1])));
      const double rich = v[2] + (v[2] - v[1]) / (std::pow(2.0, p) - 1.0);
      EXPECT_NEAR(p, 2.0, 0.2) << name << k;
      // Timoshenko bound (βL)²(r/L)²(1 + E/κG) with B1's r² = I/A = 3.9e-4 m², L = 8 m:
      // 1.5e-3 for mode 3, 2e-4 for mode 1.
      const double bl = std::vector<double>{1.875, 4.694, 7.855}[k - 1];
      const double bound = bl * bl * (1.5e-7 / 3.84e-4) / 64.0 * (1.0 + 6.895e10 / (5.0 / 6.0 * 2.6519e10));
      EXPECT_LT(std::abs(rich / exact[k - 1] - 1.0), bound) << name << k << ": " << rich << " vs " << exact[k - 1];
    }
  }
}
