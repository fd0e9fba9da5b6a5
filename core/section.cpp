#include "core/section.hpp"

#include <cmath>

namespace rfem {

Section box_section(const std::string& name, double outer, double inner) {
  Section s;
  s.name = name;
  s.A = outer * outer - inner * inner;
  s.Iy = s.Iz = (std::pow(outer, 4) - std::pow(inner, 4)) / 12.0;
  const double t = 0.5 * (outer - inner), b = 0.5 * (outer + inner);
  s.J = b * b * b * t;  // Bredt: 4 A_m² t / perimeter with A_m = b², perimeter = 4b
  s.kappa_y = s.kappa_z = 0.44;
  return s;
}

}  // namespace rfem
