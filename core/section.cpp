#include "section.hpp"

#include <cmath>

#include "check.hpp"

namespace rfem {

void Material::check() const {
  const std::string who = "material " + name + ": ";
  require_positive(who + "E", E);
  require_positive(who + "G", G);
  require_positive(who + "rho", rho);
}

void Section::check() const {
  const std::string who = "section " + name + ": ";
  require_positive(who + "A", A);
  require_positive(who + "Iy", Iy);
  require_positive(who + "Iz", Iz);
  require_positive(who + "J", J);
  require_positive(who + "kappa_y", kappa_y);
  require_positive(who + "kappa_z", kappa_z);
  for (int i = 1; i < 3; ++i) require_finite(who + "offset", offset[i]);
}

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
