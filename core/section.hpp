#pragma once
// Materials and beam cross-sections of a flexible link. SI units.
#include <string>

#include "types.hpp"

namespace rfem {

struct Material {
  std::string name;
  double E = 0.0;    ///< Young's modulus [Pa]
  double G = 0.0;    ///< shear modulus [Pa]
  double rho = 0.0;  ///< density [kg/m³]
  /// Throws std::invalid_argument unless E, G and rho are positive.
  void check() const;
};

/// A cross-section in the link frame: the link axis is x, the section lies in y–z.
/// Iy = ∫z² dA bends about y (deflection along z), Iz = ∫y² dA bends about z (deflection along y).
struct Section {
  std::string name;
  double A = 0.0;         ///< area [m²]
  double Iy = 0.0;        ///< second moment about y [m⁴]
  double Iz = 0.0;        ///< second moment about z [m⁴]
  double J = 0.0;         ///< torsion constant [m⁴]
  double kappa_y = 5.0 / 6.0;  ///< shear coefficient for shear along y
  double kappa_z = 5.0 / 6.0;  ///< shear coefficient for shear along z
  Vec3 offset = Vec3::Zero();  ///< mass centre relative to the elastic axis (x component ignored) [m]
  /// Throws std::invalid_argument unless A, Iy, Iz, J and the shear coefficients are positive.
  void check() const;
};

/// Thin-walled square box from outer and inner side (the paper's links 1 and 2: 0.05 m / 0.0475 m).
/// J by Bredt's formula on the mid-line, κ = 0.44 (thin square tube, Cowper).
Section box_section(const std::string& name, double outer, double inner);

}  // namespace rfem
