#pragma once
// A simulation a caller steps (MuJoCo's mj_step loop, Drake's AdvanceTo): built from a case, it
// keeps the integrator's state between calls. advance(t) integrates to t, the last step ending
// exactly there; between calls the caller reads the state and sensors, holds joint torques or PD
// references (zero-order hold), takes the state out and starts other simulations from it. The run
// is recorded like `rfem run`'s (studies/runs.hpp: observers, series, peaks, energy balance) and,
// with an output path, into a results file of the same layout, group "run". ESDIRK only (BDF's IDA
// keeps a history that cannot be handed over). A controller at a sample rate (run_controlled) is a
// loop over advance().
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rfem/studies/linearize.hpp"
#include "rfem/studies/runs.hpp"

namespace rfem {

/// Everything a simulation needs to go on from where it was: the integrator's state (time,
/// coordinates, rates, accelerations, step size, energy integrals) and the drives' held values,
/// with the signature of its model (another model's state is refused).
struct SimulationState {
  std::string model;           ///< model_signature() of the model it belongs to
  IntegratorState integrator;
  /// Per joint, what it holds: kHeldNone, kHeldTorque (τ) or kHeldReference (q_ref, q̇_ref, τ_ff).
  std::vector<double> drives;
  /// What the joints' laws remember (pack_law_memory: a digital PD's held and delayed values).
  std::vector<double> laws;
  /// Where the sensors' noise is (SensorBank::save): the recorded rows' streams (before the row at
  /// the state's time, which a simulation started from it records again), then the snapshots'.
  std::vector<double> sensors;
  double time() const { return integrator.t; }
  /// As doubles (a version first), and back (std::invalid_argument for text that is not one).
  std::vector<double> pack() const;
  static SimulationState unpack(const std::string& model, const std::vector<double>& x);
};

/// "n=12; links=link:12; joints=hub:revolute:torque,...; unknowns=73": what a state must match.
std::string model_signature(const Model& model, const std::vector<JointInput>& inputs);
/// A state in an HDF5 file of its own (dataset state/packed, attribute state/model) and back
/// (ResultsError / std::invalid_argument naming the file).
void save_state(const SimulationState& state, const std::string& path);
SimulationState load_state(const std::string& path);

struct SimulationOptions {
  int n = 0;                 ///< rfes in all links (0: the case's own)
  int threads = 0;           ///< the kernels' team (0: OpenMP's default)
  std::string output;        ///< results file ("": none)
  std::string made_by = "rfem::Simulation";  ///< kept in the file (command_line)
  /// Who steps it, kept in the file (driven_by): `rfem run --resume` refuses a run whose inputs came
  /// from its caller. "" for a case's own run (from a saved state: run_from_state).
  std::string driven_by = "rfem::Simulation";
  bool keep_series = false;  ///< keep every series in memory (finish()'s RunResult::series)
  /// Start from this state instead of the case's initial state (its time; the results start there).
  std::shared_ptr<const SimulationState> state;
  std::vector<RunObserver*> observers;  ///< the caller keeps them alive while the simulation lives
  Warnings warn;
  StopToken stop;            ///< request() ends the current advance() within a step (Interrupted)
  /// Called from advance()'s step loop at most every heartbeat_interval seconds of wall time (to
  /// poll something of the caller's: Python's Ctrl-C); if it throws, the run fails with its message.
  std::function<void(double t, long steps)> heartbeat;
  double heartbeat_interval = 0.1;  ///< [s]
};

/// What a lab measures at the simulation's time: joint encoders and torques (applied, or required
/// by a prescribed motion), every link's tip in {0} and its deflection in {r}, and the case's sensors.
struct Snapshot {
  double t = 0.0;
  VecX joint_q, joint_v, joint_tau;        ///< per joint [rad or m, /s, N m or N]
  std::vector<Vec3> tip_position;          ///< per link, in {0} [m]
  std::vector<Vec3> tip_deflection;        ///< per link: u1, u2 [m], θ [rad] in {r}
  /// The case's [[sensors]] by name, as measured (noise, resolution; studies/sensors.hpp).
  std::vector<std::pair<std::string, std::vector<double>>> sensors;
};

class Simulation {
 public:
  /// CaseError for a case that cannot run (studies/runs.hpp: check_runnable) or BDF;
  /// std::invalid_argument for a state of another model; the results file, if any, is created here
  /// (ResultsError for a path it cannot create).
  Simulation(const Case& cs, SimulationOptions opts);
  ~Simulation();  ///< finishes the run if the caller did not (status "interrupted (stopped)")
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) = delete;
  Simulation(const Simulation&) = delete;
  Simulation& operator=(const Simulation&) = delete;

  const Model& model() const;
  std::shared_ptr<const Model> shared_model() const;
  double time() const;
  double t_end() const;  ///< the case's simulation.t_end: advance() goes no further
  /// Every coordinate and rate in the model's order (rfes first, link by link, then the joints).
  VecX q() const;
  VecX v() const;
  /// Their names: "LINK/rfeK/x1" … "LINK/rfeK/phi3" (K from 1), then the joints' names.
  std::vector<std::string> coordinate_names() const;
  std::vector<std::string> joint_names() const;
  /// Per joint: "motion", "torque" or "feedback" (what set_torque and set_reference accept).
  std::vector<std::string> joint_inputs() const;

  /// Holds the torque (force) τ on a force-input joint from now until changed, replacing its law
  /// from the case. std::invalid_argument for an unknown joint, a prescribed one, a τ that is not finite.
  void set_torque(const std::string& joint, double tau);
  /// Holds the reference of a PD joint (`feedback`): τ = τ_ff + kp (q_ref − q) + kd (q̇_ref − q̇)
  /// with the case's kp, kd, until changed.
  void set_reference(const std::string& joint, double q_ref, double v_ref = 0.0, double tau_ff = 0.0);
  /// Back to the case's own law for that joint.
  void release(const std::string& joint);

  /// Integrates to t (time() ≤ t ≤ t_end()), the last step ending exactly at t, every output of the
  /// case's grid on the way recorded. Running while t < t_end, Completed at t_end; after Failed or
  /// Interrupted it stays there (finish() records it).
  RunStatus advance(double t);
  /// The measurements at the current time.
  Snapshot snapshot();
  /// The state now, to save or to start other simulations from.
  SimulationState state() const;
  /// The linear model about the state now (studies/linearize.hpp), the laws in force included: at
  /// rest (`equilibrium`: q̈ = 0, the free joints' inputs u0 those that hold it) or on the motion
  /// (q̈ the state's own). Sparse from O(1) evaluations of the equations whatever n (checked
  /// against their directional differences; std::runtime_error if they disagree), or `dense`:
  /// column by column (9 evaluations per state: the reference).
  LinearModel linearize(bool equilibrium = true, bool dense = false);
  /// Ends the run with `status` (default: how advance() left it — completed if at t_end, else
  /// interrupted (stopped)), closes the results file and returns the run's record (again on later
  /// calls). Afterwards only the getters work (the rest throws std::logic_error).
  RunResult finish(std::optional<RunStatus> status = std::nullopt);
  bool finished() const;
  /// The run's status so far.
  RunStatus status() const;
  /// The results file ("" if none).
  const std::string& output() const;
  /// A table for the run's group of the results file (the controller's record), written when the
  /// run finishes; ignored without a file.
  void record_table(const std::string& name, const Table& table, const std::vector<std::string>& columns,
                    const std::vector<std::string>& units, const std::string& description);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// What a controller returns at a sample: torques of force-input joints and references of PD
/// joints, by joint name (held until its next output takes effect).
struct ControlOutput {
  std::map<std::string, double> torques;
  struct Reference {
    double q = 0.0, v = 0.0, tau_ff = 0.0;
  };
  std::map<std::string, Reference> references;
};
/// f(t, y): the controller, called at t = k·sample_time with the snapshot y there.
using Controller = std::function<ControlOutput(double t, const Snapshot& y)>;

struct ControlOptions {
  double sample_time = 0.0;  ///< [s], > 0 and ≤ the run's t_end
  int delay = 0;             ///< whole samples between a controller's call and its output taking effect
};

/// Runs the case with a digital controller in the loop: at every sample time t_k = k·sample_time
/// (k = 0, 1, …) the controller sees the snapshot there; its output takes effect at t_{k+delay}
/// and is held until the next one does (zero-order hold); the steps end at the sample times.
/// Before the first output takes effect the joints follow the case's laws. The controller's calls
/// are recorded in the results file (run/control: the time and each joint's held value). A
/// controller that throws, or returns an unknown joint or a value that is not finite, ends the run
/// `failed: controller: …` with every earlier row kept.
RunResult run_controlled(const Case& cs, SimulationOptions opts, const Controller& controller, const ControlOptions& control);

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
