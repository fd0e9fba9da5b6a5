#pragma once
// The Jacobians of the equations of motion (docs/formulation.md §8) over the full unknowns — every
// rfe coordinate, then the free joints, in EquationsOfMotion's order — as sparse matrices, from
// O(1) evaluations of the generalised forces whatever n is (a column per evaluation would be
// O(n²), the dense algebra after it O(n³)):
//   - an rfe's rows see its own coordinates, its neighbours' through the sdes, and the nodes that
//     move its link; so the coordinates of rfes three apart in every link (the same axis) are
//     perturbed together — 18 evaluations per difference — and each row's change belongs to the
//     one rfe of the group within one of it;
//   - the rows of the tree's nodes (the joints, the rfes that carry something) see every rfe: the
//     workspace sums each rfe's moments alone (chunks of one rfe), and a node row's change is
//     split among the group's rfes through those moments (add_link_moments_to_nodes: linear);
//   - the nodes' coordinates, the free joints, and the rfes next to a carrying rfe are perturbed
//     one at a time.
// Differences as the dense linearisation (central at h and 2h, Richardson; q̈ exact, one unit step).
// The caller checks the result against directional differences of its own residual.
#include <array>
#include <utility>
#include <vector>

#include "../assembly/assemble.hpp"
#include "../solvers/inputs.hpp"
#include "../solvers/reduction.hpp"

namespace rfem {

/// Step of the central differences [m, rad, m/s, rad/s]. The residual is smooth (trigonometric in
/// the rotations, quadratic in the rates) but computed from positions of the model's size, so
/// round-off puts ~ε L / h into a column; with Richardson's extrapolation (truncation O(h⁴)) h = 1e-5
/// keeps both near 1e-10 of it (Kane's beam: its frequencies within 3e-10 of rfem modes; 1e-6 and
/// 1e-4 measured alike, 1e-3 3e-10 from truncation).
constexpr double kLinearizationStep = 1e-5;

/// Richardson's extrapolation of central differences at h and 2h (truncation O(h⁴)) as offsets and
/// weights: f' ≈ Σ_s w_s f(x + d_s) = (8 (f(h) − f(−h)) − (f(2h) − f(−2h))) / 12h.
inline std::array<std::pair<double, double>, 4> richardson(double h = kLinearizationStep) {
  return {{{h, 8 / (12 * h)}, {-h, -8 / (12 * h)}, {2 * h, -1 / (12 * h)}, {-2 * h, 1 / (12 * h)}}};
}

/// Σ_s w_s a(d_s) for Richardson's offsets: the derivative of two vectors `at(d, a, b)` evaluates
/// at offset d (into da, db).
template <class At>
void richardson_difference(At&& at, VecX& da, VecX& db, double h = kLinearizationStep) {
  VecX a, b;
  bool first = true;
  for (const auto& [d, w] : richardson(h)) {
    at(d, a, b);
    if (first) {
      da = w * a;
      db = w * b;
      first = false;
    } else {
      da += w * a;
      db += w * b;
    }
  }
}

struct EquationsJacobian {
  SparseMat K, D, M;       ///< ∂r/∂q, ∂r/∂q̇, ∂r/∂q̈: unknown rows × unknown columns (full unknowns)
  MatX tau_q, tau_v, tau_a;  ///< every joint's torque (required, or its law's) × the same columns
  VecX tau0;               ///< the torques at the point
  std::vector<int> coords; ///< each full unknown's coordinate in the model
  int evaluations = 0;     ///< of the generalised forces
};

/// The Jacobians at (t, q, v, a) — full coordinates, prescribed joints on their laws — of
/// r = F_u(q, q̇, q̈) − τ_u(t, q, q̇) over the full unknowns (the model's 6n rfe coordinates in order,
/// then each joint with a torque law, in joint order). Runs on one thread.
EquationsJacobian equations_jacobian(const Model& model, const std::vector<JointInput>& inputs, const ForceTerms& terms,
                                     double t, const VecX& q, const VecX& v, const VecX& a);

}  // namespace rfem
