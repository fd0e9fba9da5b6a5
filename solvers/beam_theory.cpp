#include "beam_theory.hpp"

#include <cmath>

namespace rfem::beam {

double cantilever_beta_l(int k) {
  double x = (2 * k - 1) * M_PI / 2.0;
  if (k == 1) x = 1.875;
  for (int it = 0; it < 100; ++it) {  // Newton on f = cos x cosh x + 1
    const double f = std::cos(x) * std::cosh(x) + 1.0;
    const double df = -std::sin(x) * std::cosh(x) + std::cos(x) * std::sinh(x);
    const double dx = f / df;
    x -= dx;
    if (std::abs(dx) < 1e-15 * x) break;
  }
  return x;
}

namespace {
// Newton from x0 on f (f' given); the roots below lie within 1e-3 of their asymptotes x0.
template <class F, class DF>
double newton_root(double x, F f, DF df) {
  for (int it = 0; it < 100; ++it) {
    const double dx = f(x) / df(x);
    x -= dx;
    if (std::abs(dx) < 1e-15 * x) break;
  }
  return x;
}
}  // namespace

double pinned_free_beta_l(int k) {  // sin x cosh x − cos x sinh x = 0 (÷ cosh x: no overflow)
  return newton_root((4 * k + 1) * M_PI / 4, [](double x) { return std::sin(x) - std::cos(x) * std::tanh(x); },
                     [](double x) { const double h = 1 / std::cosh(x); return std::cos(x) + std::sin(x) * std::tanh(x) - std::cos(x) * h * h; });
}

double free_free_beta_l(int k) {  // cos x − 1/cosh x = 0
  return newton_root((2 * k + 1) * M_PI / 2, [](double x) { return std::cos(x) - 1 / std::cosh(x); },
                     [](double x) { return -std::sin(x) + std::tanh(x) / std::cosh(x); });
}

double cantilever_tip_mass_beta_l(double mu, double eta, int k) {
  auto f = [&](double x) {  // the frequency equation divided by cosh x (no overflow)
    const double c = std::cos(x), s = std::sin(x), h = 1.0 / std::cosh(x), t = std::tanh(x);
    return h + c + x * mu * (c * t - s) - x * x * x * eta * (s + t * c) + x * x * x * x * mu * eta * (h - c);
  };
  int found = 0;
  const double dx = 1e-3;  // roots are ~π apart or more; the scan cannot step over a pair
  for (double a = dx; a < 1e3; a += dx) {
    if (f(a) * f(a + dx) > 0.0) continue;
    if (++found < k) continue;
    double lo = a, hi = a + dx;
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      (f(lo) * f(mid) <= 0.0 ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
  }
  return NAN;
}

double cantilever_omega(const Segment& s, ModeKind kind, int k) {
  const double L = s.length, E = s.material.E, G = s.material.G, rho = s.material.rho;
  const Section& c = s.section;
  const double rod = (2 * k - 1) * M_PI / (2.0 * L);
  switch (kind) {
    case ModeKind::Axial: return rod * std::sqrt(E / rho);
    case ModeKind::Torsion: return rod * std::sqrt(G * c.J / (rho * (c.Iy + c.Iz)));
    case ModeKind::BendingY: {  // deflection along y bends about z
      const double b = cantilever_beta_l(k) / L;
      return b * b * std::sqrt(E * c.Iz / (rho * c.A));
    }
    case ModeKind::BendingZ: {
      const double b = cantilever_beta_l(k) / L;
      return b * b * std::sqrt(E * c.Iy / (rho * c.A));
    }
    case ModeKind::Rigid: return 0.0;  // a clamped cantilever has none
  }
  return 0.0;
}

double cantilever_omega_timoshenko(const Segment& s, ModeKind kind, int k) {
  const bool y = kind == ModeKind::BendingY;  // deflection along y bends about z
  const double L = s.length, E = s.material.E, G = s.material.G, rho = s.material.rho, A = s.section.A;
  const double I = y ? s.section.Iz : s.section.Iy, kappa = y ? s.section.kappa_y : s.section.kappa_z;
  const double r2 = I / (A * L * L), s2 = E * I / (kappa * G * A * L * L);
  auto f = [&](double b) {
    const double root = std::sqrt((r2 - s2) * (r2 - s2) + 4.0 / (b * b));
    const double al = std::sqrt(std::max(0.0, -(r2 + s2) + root) / 2.0), be = std::sqrt(((r2 + s2) + root) / 2.0);
    const double d = (r2 - s2) * (r2 - s2);
    return 2.0 + (b * b * d + 2.0) * std::cosh(b * al) * std::cos(b * be) -
           b * (r2 + s2) / std::sqrt(1.0 - b * b * r2 * s2) * std::sinh(b * al) * std::sin(b * be);
  };
  // The Timoshenko root lies below the Euler–Bernoulli one b = (βL)²: scan down from it for the
  // sign change, then bisect.
  const double b_eb = std::pow(cantilever_beta_l(k), 2);
  double hi = b_eb * 1.0001, lo = hi;
  const double fhi = f(hi);
  for (int i = 0; i < 4000; ++i) {
    lo = hi * (1.0 - 1e-4 * (i + 1));
    if ((f(lo) > 0) != (fhi > 0)) break;
  }
  double a = lo, c = b_eb * 1.0001;
  for (int i = 0; i < 200 && c - a > 1e-15 * c; ++i) {
    const double m = 0.5 * (a + c);
    ((f(m) > 0) == (f(a) > 0) ? a : c) = m;
  }
  const double b = 0.5 * (a + c);
  return b * std::sqrt(E * I / (rho * A * std::pow(L, 4)));
}

double cantilever_tip_deflection(const Segment& s, double P, bool along_z) {
  const double L = s.length;
  const double I = along_z ? s.section.Iy : s.section.Iz;
  const double kappa = along_z ? s.section.kappa_z : s.section.kappa_y;
  return P * L * L * L / (3.0 * s.material.E * I) + P * L / (kappa * s.material.G * s.section.A);
}

double cantilever_tip_rotation(const Segment& s, double P, bool along_z) {
  const double L = s.length;
  const double I = along_z ? s.section.Iy : s.section.Iz;
  return P * L * L / (2.0 * s.material.E * I);
}

}  // namespace rfem::beam
