#pragma once
// Linear models about a state (docs/formulation.md §8): the equations of motion over the unknowns
// (rfe coordinates and free joints), r_u(q, q̇, q̈) − u = 0 with u a torque added at every free
// joint, expanded to first order about (q0, q̇0, q̈0):
//   M δq̈ + D δq̇ + K δq = B δu,    δy = Cq δq + Cv δq̇ + Ca δq̈,
// M = ∂r/∂q̈ (exact: r is linear in q̈), D = ∂r/∂q̇ (sde and drive damping, the PD laws' kd,
// gyroscopic terms about a moving state), K = ∂r/∂q (elastic with its geometric term, gravity,
// centrifugal, the PD laws' kp), by central differences of the residual the integrators solve —
// the same equations, laws included, whatever terms they hold: sparse, from O(1) evaluations of it
// (studies/linear_jacobian.hpp), checked against its directional differences; or column by column
// (`dense`, O(n) evaluations: the reference). Outputs y: every link's tip deflection, every joint's
// coordinate, rate and torque (applied or required), the case's sensors (exact, no noise). First
// order with x = (δq, δq̇): ẋ = A x + B u, y = C x + D u (dense: moderate sizes only).
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "../core/model.hpp"
#include "../simulation/simulation.hpp"
#include "../solvers/equations.hpp"
#include "../solvers/reduction.hpp"
#include "linear_jacobian.hpp"

namespace rfem {

class ResultsWriter;

struct LinearModel {
  double t = 0.0;                    ///< the state's time [s]
  bool equilibrium = true;           ///< about rest (q̈0 = 0, u0 holds it) or a moving state (q̈0 its own)
  std::vector<std::string> states;   ///< the unknowns: "LINK/rfeK/x1" … "phi3", free joints by name
  std::vector<std::string> inputs;   ///< free joints: a torque [N m] (or force [N]) added to each
  std::vector<std::string> outputs;  ///< "LINK/tip_u1", "JOINT/q", "JOINT/tau", sensor columns
  std::vector<std::string> output_units;
  SparseMat M, D, K, B;  ///< states × states (B: × inputs)
  MatX Cq, Cv, Ca;       ///< outputs × states
  VecX q0, v0, a0;  ///< the operating point (unknowns)
  VecX u0;          ///< the inputs' values there: the residual at the free joints (what holds it)
  VecX y0;          ///< the outputs there
  /// max |r| over the rfe rows at the operating point, relative to the largest elastic or inertial
  /// force term of a column of K or M (≪ 1 at an equilibrium or on the equations' own motion).
  double imbalance = 0.0;
  /// ẋ = A x + Bs u, y = C x + Ds u with x = (δq, δq̇) (dense, M solved by sparse Cholesky);
  /// std::invalid_argument above kMaxDenseStates states (descriptor() is sparse).
  void state_space(MatX& A, MatX& Bs, MatX& C, MatX& Ds) const;
  /// The same model as a sparse descriptor system of any size, x = (δq, δq̇, δq̈) (3N states):
  ///   E ẋ = A x + B u,  y = C x,   E = [I 0 0; 0 I 0; 0 0 0],  A = [0 I 0; 0 0 I; −K −D −M],
  ///   B = [0; 0; B],  C = [Cq Cv Ca]
  /// (the last block row the equations of motion, algebraic: index 1, as M is invertible).
  void descriptor(SparseMat& E, SparseMat& A, SparseMat& Bd, SparseMat& C) const;
  /// A 2N × 2N dense A of 3 000 states takes 288 MB.
  static constexpr int kMaxDenseStates = 3000;
  /// Files hold the dense first-order model up to this many states (A: 32 MB), M, D, K, B always.
  static constexpr int kFileDenseStates = 1000;
  int evaluations = 0;  ///< of the equations (the sparse method: independent of n)
  /// The first-order states' names: states, then "d/dt NAME".
  std::vector<std::string> first_order_states() const;
};

/// What a linearisation evaluates: the residual r_u and the outputs at (q_u, q̇_u, q̈_u).
using LinearEvaluation = std::function<void(const VecX& qu, const VecX& vu, const VecX& au, VecX& r, VecX& y)>;

/// Column by column: central differences of `f` about (q0, v0, a0) (kLinearizationStep in q, q̇,
/// Richardson; q̈ exact). `free_rows`: the unknown rows of the free joints (the inputs' columns of B).
void linearize_about(const LinearEvaluation& f, const VecX& q0, const VecX& v0, const VecX& a0,
                     const std::vector<int>& free_rows, int rfe_rows, LinearModel& lin);

/// The outputs at full coordinates q, v, a and every joint's torque.
using OutputEvaluation = std::function<void(const VecX& q, const VecX& v, const VecX& a, const VecX& tau, VecX& y)>;

/// Sparse (studies/linear_jacobian.hpp): the Jacobians of `eq`'s equations at time t about the
/// unknowns' (q0, v0, a0), over the full unknowns and projected on reduced links (K = Pᵀ K_full P);
/// the outputs `g` differenced column by column (no equations), τ's part through the torque rows.
/// Then checked against directional differences of `f` (eq's residual and g) along one direction
/// touching every unknown: std::runtime_error naming the row or output if a row disagrees by more
/// than 1e-6 of its terms plus round-off. lin's states and outputs must be set.
void linearize_sparse(EquationsOfMotion& eq, double t, const LinearEvaluation& f, const OutputEvaluation& g,
                      const VecX& q0, const VecX& v0, const VecX& a0, const std::vector<int>& free_rows, int rfe_rows,
                      LinearModel& lin);

/// B (the free rows' unit columns), u0 = r0 there, q0, v0, a0, y0 and the imbalance of `lin`,
/// whose M, D, K are set.
void set_operating_point(LinearModel& lin, const VecX& q0, const VecX& v0, const VecX& a0, const VecX& r0, const VecX& y0,
                         const std::vector<int>& free_rows, int rfe_rows);

/// Largest difference between J w and `dJw`, the directional difference of the equations along w
/// (what a missed entry shows; its row into `row`), row by row relative to (|J| |w|)_i + 1e-9 of
/// the largest + 1e6 noise_i: a mismatch above 1e-6 is more than 1e-6 of the row's terms plus the
/// difference's round-off noise_i.
double directional_mismatch(const SparseMat& J, const VecX& w, const VecX& dJw, const VecX& noise,
                            Eigen::Index* row = nullptr);

/// The first-order model's lowest `count` modes (frequency [Hz], damping ratio), one per
/// oscillating pair of eigenvalues of A: dense up to 16 states, else shift-invert
/// Arnoldi (Spectra) on the sparse pencil K + σD + σ²M.
std::vector<std::pair<double, double>> linear_modes(const LinearModel& lin, int count);

/// Writes `lin` into `file` (group "linear": M, D, K, B sparse as (row, column, value) tables, 0-based,
/// with attributes rows and matrix_columns; Cq, Cv, Ca and, up to kFileDenseStates states, A, Bs, C,
/// Ds as tables with their row and column names; the operating point, attributes t and equilibrium).
void write_linear(ResultsWriter& file, const LinearModel& lin);

/// The linear model of a simulation about its state now, the laws in force included: at rest
/// (`equilibrium`: q̈ = 0, the free joints' inputs u0 those that hold it) or on the motion (q̈ the
/// state's own). Sparse from O(1) evaluations of the equations whatever n (checked against their
/// directional differences; std::runtime_error if they disagree), or `dense`: column by column (9
/// evaluations per state: the reference).
LinearModel linearize(Simulation& sim, bool equilibrium = true, bool dense = false);

/// What rfem.linearize / `rfem linearize` asks for.
struct LinearizeRequest {
  int n = 0;        ///< rfes in all links (0: the case's own)
  int threads = 1;  ///< the kernels' team
  /// About this state (its time, the same model only); null: the case's initial state (its static
  /// equilibrium, simulation.initial = "static") at t = 0.
  std::shared_ptr<const SimulationState> state;
  bool equilibrium = true;  ///< q̈ = 0 (at rest) or the state's own accelerations
  bool dense = false;       ///< column by column (the reference) instead of the sparse method
};
/// The case's linear model. CaseError for a case that cannot run (check_runnable, integrator "bdf":
/// linearised with the ESDIRK equations — the same equations), std::invalid_argument for another
/// model's state.
LinearModel linearize(const Case& cs, const LinearizeRequest& rq);

}  // namespace rfem
