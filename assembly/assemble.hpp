#pragma once
// Global assembly over rfes and sdes (OpenMP). Per-rfe kernels write their own rows and slots;
// sdes are coloured by parity (sde e touches rfes e−1 and e) so no two threads write one slot;
// base-row moments are reduced over fixed chunks of rfes in a fixed order, so results do not
// depend on the thread count.
#include "assembly/pattern.hpp"
#include "core/kinematics.hpp"

namespace rfem {

/// Smallest number of rfes for which assembly runs in parallel (default 256; tests set 1 to
/// exercise the parallel paths on small models).
void set_parallel_min_rfes(int n);

/// Which generalised forces to include (inputs τ are never included: the caller adds them).
struct ForceTerms {
  bool inertia = true, gravity = true;
  bool sde = true;  ///< elastic and damping forces of the sdes
  /// Velocity-product (Coriolis, centrifugal) terms h of the inertial force. Off only to show what
  /// a model without them gets wrong (tests): then ε = M(q) a.
  bool velocity_products = true;
};

/// F = ε(q, v, a) + ∂V_g/∂q + ∂V_e/∂q + sde damping for all 6n + m coordinates (flexible first).
void generalised_forces(const Model& model, const VecX& q, const VecX& v, const VecX& a,
                        const ForceTerms& terms, VecX& F);

/// Coefficients of the matrix S = mass·M + damping·C + stiffness·K assembled into the pattern.
/// K holds the sde stiffness (with its geometric term), and on request the gravity stiffness and
/// the centrifugal (inertial) stiffness of the rfe blocks at the base velocity in v.
struct MatrixTerms {
  double mass = 0.0, damping = 0.0, stiffness = 0.0;
  bool gravity = false;
  bool inertial = false;
};

/// Assembles S into `values` (pattern.nnz()); base_col[j] is joint j's column or −1 if held.
/// If `sde_stiffness` is given, the sde stiffness alone (K with stiffness = 1, no gravity or
/// inertial terms) goes there in the same pass (the Newton solve needs both S and K).
void assemble_matrix(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                     const VecX& q, const VecX& v, const MatrixTerms& terms, std::vector<double>& values,
                     std::vector<double>* sde_stiffness = nullptr);

/// The symmetric matrix of a pattern's values, dense (tests and small systems).
MatX to_dense(const BorderedPattern& pattern, const std::vector<double>& values);

struct Energies {
  double kinetic = 0.0, elastic = 0.0, gravity = 0.0;
  double dissipation_rate = 0.0;  ///< power dissipated in the sdes [W]
};
Energies energies(const Model& model, const VecX& q, const VecX& v);

/// Views of one rfe's coordinates in a full coordinate vector.
inline Vec6 rfe_coords(const VecX& x, int k) { return x.segment<6>(6 * k); }
/// Coordinates of the rfe left of sde e (zeros for rfe_0, which is rigid with {r}).
inline Vec6 left_coords(const VecX& x, int e) { return e > 0 ? rfe_coords(x, e - 1) : Vec6::Zero().eval(); }
/// The base part of a full coordinate vector.
inline VecX base_coords(const Model& model, const VecX& x) { return x.tail(model.m()); }

}  // namespace rfem
