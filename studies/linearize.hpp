#pragma once
// Linear models about a state (docs/formulation.md §8): the equations of motion over the unknowns
// (rfe coordinates and free joints), r_u(q, q̇, q̈) − u = 0 with u a torque added at every free
// joint, expanded to first order about (q0, q̇0, q̈0):
//   M δq̈ + D δq̇ + K δq = B δu,    δy = Cq δq + Cv δq̇ + Ca δq̈,
// M = ∂r/∂q̈ (exact: r is linear in q̈), D = ∂r/∂q̇ (sde and drive damping, the PD laws' kd,
// gyroscopic terms about a moving state), K = ∂r/∂q (elastic with its geometric term, gravity,
// centrifugal, the PD laws' kp), by central differences of the residual the integrators solve —
// the same equations, laws included, whatever terms they hold. Outputs y: every link's tip
// deflection, every joint's coordinate, rate and torque (applied or required), the case's sensors
// (exact, no noise). First order with x = (δq, δq̇): ẋ = A x + B u, y = C x + D u.
#include <functional>
#include <string>
#include <vector>

#include "rfem/core/model.hpp"
#include "rfem/solvers/equations.hpp"

namespace rfem {

class ResultsWriter;

struct LinearModel {
  double t = 0.0;                    ///< the state's time [s]
  bool equilibrium = true;           ///< about rest (q̈0 = 0, u0 holds it) or a moving state (q̈0 its own)
  std::vector<std::string> states;   ///< the unknowns: "LINK/rfeK/x1" … "phi3", free joints by name
  std::vector<std::string> inputs;   ///< free joints: a torque [N m] (or force [N]) added to each
  std::vector<std::string> outputs;  ///< "LINK/tip_u1", "JOINT/q", "JOINT/tau", sensor columns
  std::vector<std::string> output_units;
  MatX M, D, K, B, Cq, Cv, Ca;
  VecX q0, v0, a0;  ///< the operating point (unknowns)
  VecX u0;          ///< the inputs' values there: the residual at the free joints (what holds it)
  VecX y0;          ///< the outputs there
  /// max |r| over the rfe rows at the operating point, relative to the largest elastic or inertial
  /// force term of a column of K or M (≪ 1 at an equilibrium or on the equations' own motion).
  double imbalance = 0.0;
  /// ẋ = A x + Bs u, y = C x + Ds u with x = (δq, δq̇) (dense; M solved by Cholesky).
  void state_space(MatX& A, MatX& Bs, MatX& C, MatX& Ds) const;
  /// The first-order states' names: states, then "d/dt NAME".
  std::vector<std::string> first_order_states() const;
};

/// What a linearisation evaluates: the residual r_u and the outputs at (q_u, q̇_u, q̈_u).
using LinearEvaluation = std::function<void(const VecX& qu, const VecX& vu, const VecX& au, VecX& r, VecX& y)>;

/// Central differences of `f` about (q0, v0, a0) (steps: 1e-6 in q, q̇; q̈ exact). `free_rows`:
/// the unknown rows of the free joints (the inputs' columns of B).
void linearize_about(const LinearEvaluation& f, const VecX& q0, const VecX& v0, const VecX& a0,
                     const std::vector<int>& free_rows, int rfe_rows, LinearModel& lin);

/// Writes `lin` into `file` (group "linear": M, D, K, B, Cq, Cv, Ca, A, Bs, C, Ds as tables with
/// their row and column names, the operating point, attributes t and equilibrium).
void write_linear(ResultsWriter& file, const LinearModel& lin);

}  // namespace rfem
