#include "solvers/beam_theory.hpp"

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
  }
  return 0.0;
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
