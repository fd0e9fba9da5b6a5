#pragma once
// Time integration of  q' = v,  M(q) v' + h(q, v) + f_el + f_g + f_d = τ  (docs/formulation.md §5) over
// the unknown coordinates: the 6n rfe coordinates and the joints under force input. Joints under
// kinematic input follow their laws; their torques come out of the base rows (inverse dynamics).
// The dissipated energy and the input work are integrated alongside.
//
// Two integrators, both on the bordered Newton matrix S = M + hγ C + (hγ)² K factorised on the
// unknowns' pattern (solvers/newton_system.hpp):
//  - `esdirk` (default): an L-stable, stiffly accurate singly diagonally implicit Runge–Kutta method
//    with an explicit first stage, order 3–5 (Kennedy & Carpenter's ESDIRK tables as shipped by
//    SUNDIALS ARKODE), written for the implicit second-order form (solvers/esdirk.cpp);
//  - `bdf`: SUNDIALS IDA (variable-step BDF, order ≤ max_order) with our CHOLMOD linear solver.
#include <functional>
#include <memory>
#include <string>

#include "equations.hpp"
#include "run_status.hpp"

namespace rfem {

enum class IntegratorKind { Esdirk, Bdf };

/// Where a run starts: the rfes in static equilibrium (gravity and, for joints with initial rates,
/// the centrifugal load) with the joints at their initial values — or undeformed. At rest relative
/// to {r} either way.
enum class InitialState { Static, Undeformed };

struct IntegratorOptions {
  IntegratorKind kind = IntegratorKind::Esdirk;
  /// ESDIRK table (an ARKODE DIRK table name without the "ARKODE_" prefix). It must have an
  /// explicit first stage, one diagonal coefficient, be stiffly accurate and embedded.
  std::string esdirk_table = "ESDIRK547L2SA2_7_4_5";
  /// Factorisation of the Newton matrix (solvers/linear_solver.hpp).
  LinearSolverKind linear_solver = LinearSolverKind::Chain;
  double t_end = 1.0;       ///< [s]
  double output_dt = 0.01;  ///< output interval [s]
  /// Relative tolerance. The default keeps the integration error of the paper's deployment below
  /// 1e-4 of the peaks of u1, u2, θ and the joint torques (README, "Performance"): a refinement
  /// study in n then measures the discretisation, not the integrator.
  double rtol = 1e-8;
  double atol = 1e-10;           ///< absolute tolerance on coordinates [m, rad]
  /// Absolute tolerance on velocities [m/s, rad/s]. Undamped stiff sde modes (the joint turning
  /// against the first sde, ω ∝ n²) carry velocities far above their tiny displacements.
  double atol_velocity = 1e-5;
  double atol_energy = 1e-6;     ///< on the dissipated-energy and input-work integrals [J] (BDF)
  double max_step = 0.0;    ///< 0: no limit
  /// ESDIRK with constant steps of this size [s] and no error control (0: adaptive). For
  /// measuring the temporal order; steps still end at the inputs' breakpoints and at t_end.
  double fixed_step = 0.0;
  long max_steps = 20000;   ///< steps per output interval before giving up
  /// Highest BDF order (bdf only). Orders above 2 are not A-stable: the undamped axial and shear
  /// sde modes (ω ~ 1e3–1e5 rad/s) would force tiny steps. BDF2 steps over them.
  int max_order = 2;
  InitialState initial = InitialState::Static;
  ForceTerms forces;  ///< all on for physics; tests switch velocity products off
  Parallelism parallel;  ///< threads of the kernels (results do not depend on it)
};

struct IntegratorStats {
  long steps = 0, residual_evals = 0, factorizations = 0, newton_iters = 0, newton_fails = 0, error_test_fails = 0;
  double last_step = 0.0;
};

struct RunOutcome {
  RunStatus status;
  double t_reached = 0.0;
  IntegratorStats stats;
  bool completed() const { return status.is_completed(); }
};

/// "esdirk" / "bdf" and back; parse returns false for an unknown name.
std::string integrator_name(IntegratorKind k);
bool parse_integrator(const std::string& name, IntegratorKind& k);
/// Throws std::invalid_argument naming what is wrong if `name` is not a usable ESDIRK table.
void check_esdirk_table(const std::string& name);
/// Throws std::invalid_argument naming the option that is not usable: non-positive or non-finite
/// times and tolerances, an output interval longer than the run, more than kMaxOutputs outputs.
void check_options(const IntegratorOptions& opts);
/// Outputs are at t_k = output_time(opts, k), k = 0 … output_count(opts): every output_dt, the last
/// one at t_end.
long output_count(const IntegratorOptions& opts);
double output_time(const IntegratorOptions& opts, long k);
/// More outputs than this (t_end / output_dt) are refused: a results file of 10⁸ rows per series.
inline constexpr double kMaxOutputs = 1e8;

using SampleSink = std::function<void(const OutputSample&)>;

/// Everything the ESDIRK integrator carries from one step to the next, taken after an accepted step
/// whose outputs have been delivered: resuming from it continues the run as if it had never stopped
/// (bit for bit with the same thread team). BDF's is its state at an output (IDA's history is not
/// kept). Written into results files as a checkpoint (simulation/state.hpp).
struct IntegratorState {
  double t = 0.0, h = 0.0;        ///< time reached [s], next step size [s]
  double err_prev = 1.0, eta = 1.0;  ///< step controller's last error, Newton's contraction estimate
  double dissipated = 0.0, input_work = 0.0;  ///< the energy integrals at t [J]
  Power power;                    ///< the power flows at t
  long next_output = 0;           ///< index of the next output (output_time)
  IntegratorStats stats;
  VecX q, v, a;                   ///< the unknowns' coordinates, rates and accelerations at t
  /// As doubles (a version number first), and back; unpack throws std::invalid_argument for a
  /// vector that is not a state of `unknowns` unknowns (−1: of any number).
  std::vector<double> pack() const;
  /// pack()'s values before q, v, a (which follow it in that order).
  std::vector<double> pack_head() const;
  static IntegratorState unpack(const std::vector<double>& x, int unknowns);
};

/// How the caller steers a run while it goes: a stop token polled at every step, and a heartbeat
/// called from the integration loop at most every `heartbeat_interval` seconds of wall time (for
/// progress, and for a caller that must poll something of its own, e.g. Python's signals). The
/// heartbeat runs on the calling thread; if it throws, the run fails with its message.
struct RunControl {
  StopToken stop;
  std::function<void(double t, long steps)> heartbeat;
  double heartbeat_interval = 0.2;  ///< [s]
  /// Called on the calling thread with the integrator's state after an accepted step (BDF: after an
  /// output) at most every `checkpoint_interval` seconds of wall time (0: never). If it throws, the
  /// run fails with its message.
  std::function<void(IntegratorState&)> checkpoint;  // (it may borrow the vectors; they are back on return)
  double checkpoint_interval = 0.0;  ///< [s]
  /// Start from this state instead of t = 0 (the outputs before state.next_output are not delivered
  /// again): ESDIRK goes on bit for bit, BDF restarts IDA there (the same solution within the
  /// tolerances). Checked against the model's unknowns.
  const IntegratorState* resume = nullptr;
};

/// Integrates from t = 0 to t_end, calling `sink` at t = 0 and every output_dt (output_time).
/// Shares the model and copies the inputs. With no unknowns (rigid manipulator, all joints
/// prescribed) it evaluates inverse dynamics only. Throws std::invalid_argument for bad options or
/// inputs that do not fit the model; every failure after the start (the integrator, the sink, the
/// equations) ends the run with status failed and its reason, the samples so far delivered.
RunOutcome integrate(std::shared_ptr<const Model> model, std::vector<JointInput> inputs, const IntegratorOptions& opts,
                     const SampleSink& sink, const RunControl& control = {});
/// The same for a model the caller keeps alive during the call.
RunOutcome integrate(const Model& model, const std::vector<JointInput>& inputs, const IntegratorOptions& opts,
                     const SampleSink& sink, const RunControl& control = {});

/// What a run will cost, known before it starts.
struct RunEstimate {
  double bytes = 0.0;          ///< peak memory of the integration [B] (measured per rfe, see .cpp)
  double residual_s = 0.0;     ///< one residual evaluation [s], timed on this machine (0 if not timed)
  double newton_setup_s = 0.0; ///< one assembly + factorisation of the Newton matrix [s] (0 if not timed)
  /// Seconds per integrator step: an ESDIRK5 step takes ~12 residual evaluations and one Newton
  /// matrix (README, "Performance"); 0 if not timed.
  double step_s() const { return 12.0 * residual_s + newton_setup_s; }
};
/// Runs with at least this many rfes get a timed estimate and a note before they start.
inline constexpr int kLargeRunRfes = 10000;
/// The memory of a run from the model's size; with `time` also one residual evaluation and one
/// Newton setup timed at the undeformed initial state (allocates what the run will allocate).
RunEstimate estimate_run(std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs,
                         const IntegratorOptions& opts, bool time);


/// The reason of a failure at the start of a run, with its time if it does not say one.
std::string at_start(const std::string& why);

/// Delivers samples to the caller's sink and heartbeat, catching what they throw: a failing sink
/// or heartbeat ends the run (failed, with its message) instead of unwinding through the
/// integrator (or IDA's C frames).
class SampleEmitter {
 public:
  SampleEmitter(const SampleSink& sink, const RunControl& control);
  /// False if the sink threw (now or before): the run must end with failure().
  bool operator()(const OutputSample& s);
  /// Calls the heartbeat if its interval has passed. False if it threw.
  bool beat(double t, long steps);
  /// Hands the state to the caller's checkpoint if its interval has passed (`st` is called only
  /// then). False if it threw.
  bool checkpoint(const std::function<IntegratorState()>& st);
  /// Whether a checkpoint is due (its interval has passed, nothing failed).
  bool checkpoint_due() const;
  /// Hands `st` to the caller's checkpoint now. False if it threw.
  bool checkpoint(IntegratorState& st);
  const IntegratorState* resume() const { return control_.resume; }
  bool failed() const { return !error_.empty(); }
  /// The status of a run ended by the sink or heartbeat.
  RunStatus failure() const { return RunStatus::failed(error_); }

 private:
  const SampleSink& sink_;
  const RunControl& control_;
  std::string error_;
  double last_beat_ = 0.0, last_checkpoint_ = 0.0;
};

}  // namespace rfem
