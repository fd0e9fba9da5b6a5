#pragma once
// Linearised modal analysis of the flexible link with the base held, or with chosen joints free:
// about the static equilibrium under gravity, or in a frame rotating with steady joint rates
// (centrifugal softening and the geometric stiffening of the sdes included; gyroscopic coupling
// neglected, so the problem stays symmetric: K φ = ω² M φ over the rfe coordinates and the free
// joints). Dense for small systems, shift-invert Lanczos (Spectra) on the CHOLMOD factor for large
// ones. Free joints without stiffness give rigid-body modes (ω = 0, kind Rigid).
#include <string>

#include "../assembly/workspace.hpp"
#include "../core/model.hpp"

namespace rfem {

enum class ModeKind { Axial, BendingY, BendingZ, Torsion, Rigid };
std::string to_string(ModeKind k);

struct ModesResult {
  VecX omega;             ///< natural circular frequencies [rad/s], ascending
  MatX shapes;            ///< rfe coordinates, then the free joints', of each mode ((6n + f) × count), M-normalised
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
/// Problems up to this size (6n + free joints) are solved densely, larger ones by Lanczos.
constexpr int kDenseModesLimit = 600;

/// Lowest `count` modes. `vb` are the steady joint rates (empty or zero: no rotation).
/// `free`: joints (0-based) that move with the modes instead of being held; each must carry no
/// torque in the held equilibrium (else there is no equilibrium to linearise about).
/// `dense_limit`: largest 6n + f solved densely. `parallel`: the threads of its kernels (statics,
/// assembly, a reduced link's modes). Throws std::invalid_argument for bad arguments.
ModesResult compute_modes(const Model& model, const VecX& qb, const VecX& vb, int count,
                          int dense_limit = kDenseModesLimit, const std::vector<int>& free = {},
                          const Parallelism& parallel = {});

/// Coordinates of an rfe a reduced link's modes span: its rotations φ1, φ2, φ3, the last three of
/// its six (its displacements x1, x2, x3 stay unknowns of their own: solvers/reduction.hpp says why).
constexpr int kModalAxes = 3;
/// The first of them within an rfe's six coordinates.
constexpr int kModalFirst = 6 - kModalAxes;
/// A column joins a reduced link's basis when, orthogonalised against those before it, more than
/// this fraction of its norm is left (less is round-off of a direction already held).
constexpr double kNewDirection = 1e-6;

/// The most modes whose pairwise static derivatives a reduced link may add (p(p + 1)/2 vectors).
constexpr int kMaxDerivativeModes = 16;

/// The first `count` modes of link l clamped in its {r}: every joint held at qb, every other link
/// rigid (its mass carried where it sits), about the link's static equilibrium there; their rows
/// over the kModalAxes axes. What a reduced link keeps (solvers/reduction.hpp). With
/// `derivatives` = p > 0, the static modal derivatives of modes i ≤ j ≤ p follow them
/// (docs/formulation.md §9): K θ_ij = −∂²f/∂η_i∂η_j, the second-order shapes a linear basis lacks,
/// each orthogonalised against the columns before it and left out where it adds nothing (≤ 1e-6 of
/// its norm). Throws std::invalid_argument for count outside 1 … 3n, a count that cuts a pair of
/// equal frequencies, or derivatives outside 0 … min(count, kMaxDerivativeModes).
struct LinkModes {
  VecX omega;        ///< the modes' [rad/s], ascending (count values: the derivatives have none)
  MatX shapes;       ///< 3n × (count + derivatives) over kModalAxes axes per rfe, rfe by rfe (displacement rows left out)
  MatX mass_shapes;  ///< M_bb shapes (M_bb the link's mass matrix over those coordinates)
  VecX q0;           ///< the equilibrium, 6n, rfe by rfe
  std::vector<std::pair<int, int>> pairs;  ///< (i, j), from 1, of each derivative column after the modes
};
LinkModes link_modes(const Model& model, int l, const VecX& qb, int count, int derivatives = 0,
                     const Parallelism& parallel = {});

/// A mode is rigid when ω² is below this fraction of the stiffest coordinate's K_ii / M_ii (the
/// round-off level of a zero eigenvalue).
constexpr double kRigidModeFraction = 1e-12;

}  // namespace rfem
