#pragma once
// Global assembly over rfes and sdes (OpenMP), one parallel loop over fixed chunks of every link's
// rfes (assembly/workspace.hpp). A chunk evaluates its rfes and the sdes ending on them (sde e joins
// rfes e−1 and e); the first sde's share of the previous chunk's last rfe is kept aside and added
// after the loop, so no two threads write one slot, and partial sums are combined in chunk order:
// results do not depend on the thread count. Rfes that carry a joint or a link are bodies of the
// kinematic tree (core/model.hpp): the tree's pass after the loop gives their rows, and the few
// sdes at their ends are assembled serially after the loop.
#include "pattern.hpp"
#include "workspace.hpp"
#include "../core/kinematics.hpp"

namespace rfem {

/// Which generalised forces to include (inputs τ are never included: the caller adds them).
struct ForceTerms {
  bool inertia = true, gravity = true;  ///< inertia includes the joint drives' inertia J q̈
  bool sde = true;  ///< elastic and damping forces of the sdes, and the joint drives' damping and friction
  /// Velocity-product (Coriolis, centrifugal) terms h of the inertial force. Off only to show what
  /// a model without them gets wrong (tests): then ε = M(q) a.
  bool velocity_products = true;
};

/// F = ε(q, v, a) + ∂V_g/∂q + ∂V_e/∂q + sde damping for all 6n + m coordinates (model order).
/// plus every joint drive's τ_drive (core/joint_drive.hpp). If `dissipation` is given, the power
/// dissipated in the sdes and the drives [W] goes there (same pass).
/// `ws` (may be null: a temporary one) holds the thread policy and scratch.
void generalised_forces(const Model& model, const VecX& q, const VecX& v, const VecX& a,
                        const ForceTerms& terms, VecX& F, double* dissipation = nullptr, Workspace* ws = nullptr);

/// What rfe moments `m` of link `link` (a chunk's as generalised_forces sums them into the
/// workspace, or a change of them) add to the rows of the nodes that move the link, with the base
/// kinematics `bk` of that evaluation: the same terms as generalised_forces, linear in m. The
/// linear models (studies/linear_jacobian.hpp) split a change of the node rows among the rfes
/// that caused it this way.
void add_link_moments_to_nodes(const Model& model, const BaseKinematics& bk, int link, const BaseMoments& m,
                               const ForceTerms& terms, VecX& F);

/// Coefficients of the matrix S = mass·M + damping·C + stiffness·K assembled into the pattern.
/// K holds the sde stiffness (with its geometric term), and on request the gravity stiffness and
/// the centrifugal (inertial) stiffness of the rfe blocks at the base velocity in v. M includes
/// the drives' inertia J, C their ∂τ_drive/∂q̇ at v (free joints' diagonal).
struct MatrixTerms {
  double mass = 0.0, damping = 0.0, stiffness = 0.0;
  bool gravity = false;
  bool inertial = false;
};

/// Assembles S into `values` (pattern.nnz()); base_col[j] is joint j's unknown index (numbered
/// after every rfe coordinate) or −1 if held; `pattern` is BorderedPattern(model, base_col).
void assemble_matrix(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                     const VecX& q, const VecX& v, const MatrixTerms& terms, std::vector<double>& values,
                     Workspace* ws = nullptr);

/// Where assemble_matrices also puts the sdes alone: values = fk·K + fc·C (K the sde stiffness
/// with its geometric term, C the sde damping).
struct SdeTarget {
  std::vector<double>* values;
  double fk = 0.0, fc = 0.0;
};
/// S into `values` in one pass over the rfes and sdes, and the sde parts into each extra target
/// (all reset first). If `base_rows` is given, it receives the rows of every joint (held ones too)
/// of mass·M over the pattern's columns (m × pattern.size()).
void assemble_matrices(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                       const VecX& q, const VecX& v, const MatrixTerms& terms, std::vector<double>& values,
                       const std::vector<SdeTarget>& extra, MatX* base_rows = nullptr, Workspace* ws = nullptr);

struct Energies {
  double kinetic = 0.0, elastic = 0.0, gravity = 0.0;
  double dissipation_rate = 0.0;  ///< power dissipated in the sdes and the joint drives [W]
};
Energies energies(const Model& model, const VecX& q, const VecX& v, Workspace* ws = nullptr);

/// Views of rfe k of link l's coordinates in a full coordinate vector.
inline Vec6 rfe_coords(const Model& model, const VecX& x, int l, int k) { return x.segment<6>(model.rfe_index(l, k)); }
/// Coordinates of the rfe left of sde e of link l (zeros for rfe_0, which is rigid with {r}).
inline Vec6 left_coords(const Model& model, const VecX& x, int l, int e) {
  return e > 0 ? rfe_coords(model, x, l, e - 1) : Vec6::Zero().eval();
}
/// The base part of a full coordinate vector.
inline VecX base_coords(const Model& model, const VecX& x) { return model.joint_coords(x); }

}  // namespace rfem
