#pragma once
// The simulation: the only thing that advances a run (MuJoCo's mj_step loop, Drake's AdvanceTo).
// Built from a case, it keeps the stepper's state between calls. advance(t) integrates to t, the
// last step ending exactly there; between calls the caller reads the state and sensors, holds joint
// torques or PD references (zero-order hold), takes the state out and starts other simulations from
// it. `rfem run` is a Simulation per run of the procedure advanced to t_end (studies/runs.hpp); the
// run is recorded through observers (series, peaks, energy balance, checkpoints) and, with an output
// path, into a results file of the same layout, group "run". With BDF a state restarts IDA (its
// history is not handed over: the same solution within the tolerances, not bit for bit). A
// controller at a sample rate (run_controlled) is a loop over advance().
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "../solvers/stepper.hpp"
#include "run_book.hpp"
#include "state.hpp"

namespace rfem {

class SensorBank;

/// A simulation's options: a run's (simulation/run_book.hpp), and where it writes and starts from.
struct SimulationOptions : RunOptions {
  SimulationOptions() { keep_series = false; }  // (a stepped run keeps its series only if asked)
  std::string output;        ///< results file ("": none; observers may still record)
  std::string made_by = "rfem::Simulation";  ///< kept in the file (command_line)
  /// Who steps it, kept in the file (driven_by): `rfem run --resume` refuses a run whose inputs came
  /// from its caller, and such a run keeps no checkpoints. "" for a case's own run.
  std::string driven_by = "rfem::Simulation";
  /// Start from this state instead of the case's initial state (its time; the results start there).
  std::shared_ptr<const SimulationState> state;
};

/// What a lab measures at the simulation's time: joint encoders and torques (applied, or required
/// by a prescribed motion), every link's tip in {0} and its deflection in {r}, and the case's sensors.
struct Snapshot {
  double t = 0.0;
  VecX joint_q, joint_v, joint_tau;        ///< per joint [rad or m, /s, N m or N]
  std::vector<Vec3> tip_position;          ///< per link, in {0} [m]
  std::vector<Vec3> tip_deflection;        ///< per link: u1, u2 [m], θ [rad] in {r}
  /// The case's [[sensors]] by name, as measured (noise, resolution; simulation/sensors.hpp).
  std::vector<std::pair<std::string, std::vector<double>>> sensors;
};

/// The one engine that advances a run: `rfem run`'s procedure (run_case: a Simulation per run,
/// advanced to t_end), a caller's stepping and a controller's loop alike. It owns the run's model,
/// equations and stepper (solvers/stepper.hpp: ESDIRK, IDA's BDF, or inverse dynamics without
/// unknowns) and its book (RunBook); files are written by observers (simulation/recorders.hpp).
class Simulation {
 public:
  /// The case's run on its own model (opts.n rfes) and inputs, stepped by the caller. CaseError for
  /// a case that cannot run (simulation/run_book.hpp: check_runnable) or has nothing to step;
  /// std::invalid_argument for a state of another model; the results file, if any, is created here
  /// (ResultsError for a path it cannot create).
  Simulation(const Case& cs, SimulationOptions opts);
  /// Run `name` of the case's procedure on a given model and inputs (one per joint), from t = 0 or
  /// resumed from `checkpoint` (studies/resume.hpp; std::invalid_argument for another model's). A
  /// start that fails (bad options, a checkpoint that does not fit the run) is the run's status.
  Simulation(const Case& cs, std::string name, std::shared_ptr<const Model> model, std::vector<JointInput> inputs,
             SimulationOptions opts, const Checkpoint* checkpoint = nullptr);
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

  /// A sample-and-hold in the loop: f(t) is called at t = k·period for k = first, first + 1, … with
  /// time() < t < t_end() as the steps reach it (they end there, as at a digital law's samples: one mechanism,
  /// solvers/stepper.hpp), after the outputs there. f sees the simulation as a caller between two
  /// advance() calls does (snapshot, set_torque, set_reference, release; not advance); what it
  /// holds stays until it changes it. What f throws ends the run failed with its words (every row
  /// before kept). std::logic_error for BDF (its steps do not end at samples).
  void sample_every(double period, long first, std::function<void(double t)> f);
  /// Integrates to t (time() ≤ t ≤ t_end()), the last step ending exactly at t, every output of the
  /// case's grid on the way recorded. Running while t < t_end, Completed at t_end; after Failed or
  /// Interrupted it stays there (finish() records it).
  RunStatus advance(double t);
  /// The measurements at the current time.
  Snapshot snapshot();
  /// The state now, to save or to start other simulations from.
  SimulationState state() const;
  /// The stepper's state now, the inputs held since the last step in force (what a linear model is
  /// taken about: studies/linearize.hpp). std::logic_error for a run without a state.
  IntegratorState integrator_state();
  /// The equations it integrates (the caller evaluates them; it must not step them).
  EquationsOfMotion& equations();
  /// The case's sensors as a snapshot reads them (null without [[sensors]]).
  SensorBank* sensors();
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

/// Why run_controlled ended a run at a sample: the controller threw, or returned a value the loop
/// refuses (not finite). what() is the run's failure reason ("controller: … at t = … s").
class ControllerError : public std::runtime_error {
 public:
  enum class Kind { Threw, NotFinite };
  ControllerError(Kind kind, double t, const std::string& reason) : std::runtime_error(reason), kind_(kind), t_(t) {}
  Kind kind() const { return kind_; }
  double t() const { return t_; }  ///< the sample's time [s]

 private:
  Kind kind_;
  double t_;
};

struct ControlOptions {
  double sample_time = 0.0;  ///< [s], > 0 and ≤ the run's t_end
  int delay = 0;             ///< whole samples between a controller's call and its output taking effect
  /// Told of a controller's failure before the run ends with it (a caller's own error channel: a
  /// Python ValueError for a value that is not finite). What it throws is ignored.
  std::function<void(const ControllerError&)> on_error;
};

/// Runs the case with a digital controller in the loop: at every sample time t_k = k·sample_time
/// (k = 0, 1, …) the controller sees the snapshot there; its output takes effect at t_{k+delay}
/// and is held until the next one does (zero-order hold); the steps end at the sample times.
/// Before the first output takes effect the joints follow the case's laws. The controller's calls
/// are recorded in the results file (run/control: the time and each joint's held value). A
/// controller that throws, or returns an unknown joint or a value that is not finite, ends the run
/// `failed: controller: …` with every earlier row kept.
RunResult run_controlled(const Case& cs, SimulationOptions opts, const Controller& controller, const ControlOptions& control);


}  // namespace rfem
