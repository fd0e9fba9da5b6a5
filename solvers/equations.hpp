#pragma once
// The equations of motion over the unknown coordinates (docs/formulation.md §5): the 6n rfe
// coordinates and the joints under force input. With full q, v, a built from the unknowns and the
// laws of prescribed joints,
//   r_u(t, q_u, v_u, a_u) = F_u(q, v, a) − τ_u(t),   F = M(q) a + h(q, v) + f_el + f_g + f_d,
// and the required torques of prescribed joints are the base rows of F (inverse dynamics).
// Shared by every time integrator; owns the Newton system on the unknowns' bordered pattern and
// the workspace of its kernels, shares the model and keeps its own copy of the inputs (their laws
// are shared). With reduced links (solvers/reduction.hpp, built at the joints' initial values) the
// unknowns are the reduced ones: every method's q_u, v_u, a_u, r_u and base_col() are then over
// them, and the full coordinates are q0 + P q_u. Movable, not copyable.
#include <memory>

#include "../assembly/assemble.hpp"
#include "../assembly/momentum.hpp"
#include "inputs.hpp"
#include "newton_system.hpp"
#include "run_status.hpp"
#include "thread_governor.hpp"

namespace rfem {

/// One output step: full coordinates, the torque of every joint (applied or required) and energies.
struct OutputSample {
  double t = 0.0;
  VecX q, v, a;   ///< full coordinates (flexible first, base last)
  VecX tau;       ///< joint torques/forces [N m or N], applied (force input) or required (kinematic)
  Energies energy;
  Momentum momentum;  ///< of the whole manipulator in {0} (conserved for a free base without gravity)
  double dissipated = 0.0, input_work = 0.0;  ///< integrals since t = 0 [J]
  long steps = 0;        ///< integrator steps taken so far (for progress reports)
  double last_step = 0;  ///< the integrator's last step size [s]
  /// T + V + dissipated − input work [J]: constant when the energy books balance (docs/formulation.md §7).
  double energy_balance() const { return energy.kinetic + energy.elastic + energy.gravity + dissipated - input_work; }
};

/// Power flows of one state: what the energy integrals integrate.
struct Power {
  double dissipation = 0.0;  ///< sde damping [W]
  double input = 0.0;        ///< τ · q̇_b of every joint [W]
};

/// The joints' values at t = 0 (a motion law's, else the input's q0): where a reduced link's modes
/// are taken (solvers/reduction.hpp).
VecX initial_joint_values(const Model& model, const std::vector<JointInput>& inputs);

class EquationsOfMotion {
 public:
  /// One input per joint; throws std::invalid_argument otherwise (or for a null model, a null law).
  EquationsOfMotion(std::shared_ptr<const Model> model, std::vector<JointInput> inputs, const ForceTerms& terms,
                    StopToken stop = {}, LinearSolverKind solver = LinearSolverKind::Chain,
                    const Parallelism& parallel = {}, bool keep_stiffness = false);
  EquationsOfMotion(EquationsOfMotion&&) = default;
  EquationsOfMotion& operator=(EquationsOfMotion&&) = default;
  EquationsOfMotion(const EquationsOfMotion&) = delete;
  EquationsOfMotion& operator=(const EquationsOfMotion&) = delete;
  const Model& model() const { return *model_; }
  const std::vector<JointInput>& inputs() const { return inputs_; }
  /// The generalised forces' terms the residual includes.
  const ForceTerms& terms() const { return terms_; }
  /// Number of unknown coordinates (size of q_u).
  int unknowns() const { return nu_; }
  /// Joint j's column among the unknowns, −1 if prescribed.
  const std::vector<int>& base_col() const { return ubase_col_; }
  /// The modal reduction of the model's reduced links (null if none).
  const std::shared_ptr<const Reduction>& reduction() const { return reduction_; }
  /// Unknowns the integrators leave out of their error estimate, ascending: reduced links' modal
  /// derivatives (Reduction::quasi_static); empty without them.
  const std::vector<int>& quasi_static() const;
  /// Every coordinate (order 0), rate (1) or acceleration (2) at t from the unknowns' values `xu`
  /// and the prescribed joints' laws.
  VecX full_coordinates(double t, const double* xu, int order) const;
  /// The unknowns' names from every coordinate's (model order): reduced links' η as LINK/etaK.
  std::vector<std::string> unknown_names(const std::vector<std::string>& coordinate_names) const;
  bool stop_requested() const { return stop_.requested(); }
  const StopToken& stop() const { return stop_; }

  /// Full q, v, a at t from the unknowns and the prescribed laws (a_u = 0 if `au` is null).
  void expand(double t, const double* qu, const double* vu, const double* au);
  /// The full forces F and the joint torques τ at (t, q_u, v_u, a_u), without r_u; the power flows.
  Power forces(double t, const double* qu, const double* vu, const double* au, VecX& tau);
  /// r_u at (t, q_u, v_u, a_u); returns the power flows of that state.
  Power residual(double t, const double* qu, const double* vu, const double* au, double* r);
  /// An ESDIRK stage's states Q = Qk + (hγ)² A, V = Vk + hγ A (A its accelerations): begin_stage
  /// lifts Qk and Vk of a reduced model once, and stage_residual then lifts A alone (one pass over
  /// the modes instead of three a residual; Reduction::lift_stage). stage_residual is residual(t, Q,
  /// V, A, r) to round-off (exactly, without a reduced link); Q and V are the integrator's own.
  void begin_stage(const double* Qk, const double* Vk, double hg);
  Power stage_residual(double t, const double* Q, const double* V, const double* A, double* r);
  /// First-order change of a state's power flows when its accelerations move by δa_u at fixed
  /// Q_u = Q + (hγ)² δa, V_u = V + hγ δa (the last Newton update of an ESDIRK stage): required
  /// torques change by the mass rows M_bu δa, velocities by hγ δa, damping power by 2 Vᵀ C hγ δa.
  /// Uses the Newton system's last mass and damping.
  Power power_change(double t, const double* vu, const VecX& da, double hg);
  /// Accelerations of the unknowns from the equations at a state: M_uu a_u = τ_u − F_u(a_u = 0),
  /// by block elimination (O(n)). Throws if M is not positive definite.
  VecX accelerations(double t, const double* qu, const double* vu);
  /// A complete output sample at a state: torques (inverse dynamics with the accelerations au, or,
  /// if au is null, with those of the equations at that state), energies.
  /// The sample takes the equations' full q, v, a (the last evaluated state's, until the next
  /// evaluation); `give_back` returns their storage once the sample is used.
  OutputSample sample(double t, const double* qu, const double* vu, const double* au, double dissipated,
                      double input_work);
  void give_back(OutputSample& s);
  /// The inputs' breakpoints inside (0, t_end), sorted, without duplicates.
  std::vector<double> breakpoints(double t_end) const;
  /// Initial unknowns: free joints at their initial values and rates, rfes at rest relative to {r}
  /// and undeformed, or (`static_equilibrium`) in the static equilibrium of the initial joint values
  /// and rates. Throws std::runtime_error if that equilibrium cannot be found.
  void initial_state(VecX& qu, VecX& vu, bool static_equilibrium = false) const;

  NewtonSystem& newton() { return *newton_; }
  /// Solves with the Newton matrix of the last setup_newton (in place), on the kernels' team.
  void solve_newton(VecX& b) const { newton_->solve(b, team()); }
  /// IDA's 2N system with that matrix (solvers/newton_system.hpp).
  void solve_newton_bdf(const double* b, double* x) const { newton_->solve_bdf(b, x, team()); }
  /// The kernels' team now: the integrator's vector work runs on it too (solvers/team_parts.hpp).
  int team() const { return ws_.parallel.team(model_->n()); }
  /// The thread policy of every kernel the equations run (results do not depend on it). With
  /// threads = 0 a ThreadGovernor picks one thread or all by timing the residual evaluations.
  const Parallelism& parallelism() const { return ws_.parallel; }
  const ThreadGovernor& governor() const { return governor_; }
  /// The integrator times whole steps (`seconds`, `residuals` evaluated in them) for the governor
  /// instead of single residual evaluations.
  void govern_by_steps() { by_steps_ = true; }
  void report_step(double seconds, long residuals);
  /// Assembles and factorises the Newton matrix S(h) at a state. False if not positive definite.
  bool setup_newton(double t, const double* qu, const double* vu, double h);
  /// Joint torques of the last evaluated state: applied (force input) or required (kinematic).
  VecX torques(double t) const;

 private:
  std::shared_ptr<const Model> model_;
  std::vector<JointInput> inputs_;
  StopToken stop_;
  ForceTerms terms_;
  Workspace ws_;
  ThreadGovernor governor_;
  bool by_steps_ = false;
  std::vector<int> unknown_, base_col_;  // the full unknowns (every rfe coordinate, free joints)
  std::shared_ptr<const Reduction> reduction_;
  int nu_ = 0;
  std::vector<int> ubase_col_;  // base_col_ among the (reduced) unknowns
  VecX qf_, vf_, af_, rf_;      // reduced: the full unknowns' values
  VecX qkf_, vkf_;              // reduced: the stage's Qk, Vk lifted (begin_stage)
  double stage_hg_ = 0.0;
  bool in_stage_ = false;       // expand lifts by lift_stage (inside stage_residual)
  std::unique_ptr<NewtonSystem> newton_;
  std::vector<double> mass_values_;
  VecX q_, v_, a_, F_;
  bool damped_;  ///< something dissipates: sde damping or a joint drive's damping or friction
};

}  // namespace rfem
