#pragma once
// Linearised modal analysis of the flexible link with the base held: about the static equilibrium
// under gravity, or in a frame rotating with steady joint rates (centrifugal softening and the
// geometric stiffening of the sdes included; gyroscopic coupling neglected, so the problem stays
// symmetric: K φ = ω² M_ff φ). Dense for small systems, shift-invert Lanczos (Spectra) on the
// CHOLMOD factor for large ones.
#include <string>

#include "core/model.hpp"

namespace rfem {

enum class ModeKind { Axial, BendingY, BendingZ, Torsion };
std::string to_string(ModeKind k);

struct ModesResult {
  VecX omega;             ///< natural circular frequencies [rad/s], ascending
  MatX shapes;            ///< flexible coordinates of each mode (6n × count), M-normalised
  std::vector<ModeKind> kind;  ///< dominant motion (BendingY: deflection along y)
  VecX q0;                ///< the equilibrium linearised about
  bool dense = true;      ///< which eigen-solver ran
  /// Lanczos: relative change of each eigenvalue λ = ω² between two solves with different shifts
  /// (σ = 0 and σ = −λ₁): the round-off the stiff sdes put into the factorisation of K − σM,
  /// which grows like n². Above kUncertaintyTolerance the frequency is not trustworthy at this n
  /// (commands warn). Zero for the dense solver.
  VecX uncertainty;
};

constexpr double kUncertaintyTolerance = 1e-8;

/// Lowest `count` modes. `vb` are the steady joint rates (empty or zero: no rotation).
/// `dense_limit`: largest 6n solved densely.
ModesResult compute_modes(const Model& model, const VecX& qb, const VecX& vb, int count,
                          int dense_limit = 600);

}  // namespace rfem
