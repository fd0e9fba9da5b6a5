#pragma once
// A run's state, in one format: what a simulation needs to go on from where it was
// (SimulationState: the integrator's state, the drives' held values, the laws' memory, the sensors'
// noise). A Python caller takes it out and starts other simulations from it; a checkpoint
// (RunState) is the same state plus the run's own summary so far (peaks, energy balance, validity,
// wall time) and the state of every observer that accumulates over a study, packed as doubles into
// the run's group of the results file (results/writer.hpp).
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "../solvers/integrator.hpp"

namespace rfem {

struct Model;
struct JointInput;

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
  /// pack() in pieces, in order: the integrator's q, v and a are pointed to, the values between
  /// them kept in `own` (a checkpoint of n rfes then needs no copy of them). Valid while this state
  /// and `own` are.
  std::vector<std::span<const double>> pieces(std::vector<std::vector<double>>& own) const;
};

/// "n=12; links=link:12; joints=hub:revolute:torque,...; unknowns=73": what a state must match.
std::string model_signature(const Model& model, const std::vector<JointInput>& inputs);
/// A state in an HDF5 file of its own (dataset state/packed, attribute state/model) and back
/// (ResultsError / std::invalid_argument naming the file).
void save_state(const SimulationState& state, const std::string& path);
SimulationState load_state(const std::string& path);

/// A packed state's blocks: their length, then their values.
void put_block(std::vector<double>& x, const std::vector<double>& block);
/// The block at x[i] (i moves past it); std::invalid_argument(`what`) if x ends before it does.
std::vector<double> take_block(const std::vector<double>& x, size_t& i, const std::string& what);

/// A run's checkpoint: its simulation's state, the run's own summary (RunBook) and the observers'
/// states (by their state_key).
struct RunState {
  SimulationState state;  ///< (its `model` is left empty: a checkpoint belongs to its run's model)
  std::vector<double> summary;
  std::vector<std::pair<double, std::vector<double>>> observers;  ///< (key's hash, state)
  /// The state saved under `key`, or null.
  const std::vector<double>* find(const std::string& key) const;
  void add(const std::string& key, std::vector<double> state);
  /// Throws std::invalid_argument naming what does not fit (another version, another model).
  static RunState unpack(const std::vector<double>& x);
};

/// A packed RunState (the layout RunState::unpack reads) as pieces in order, pointing into the
/// state, summary and observers it is made from (SimulationState::pieces). Valid while they are.
class PackedState {
 public:
  PackedState(const SimulationState& state, const std::vector<double>& summary,
              const std::vector<std::pair<double, std::vector<double>>>& observers);
  PackedState(const PackedState&) = delete;
  PackedState& operator=(const PackedState&) = delete;
  const std::vector<std::span<const double>>& pieces() const { return pieces_; }
  size_t size() const;
  /// The pieces one after the other.
  std::vector<double> joined() const;

 private:
  std::vector<std::vector<double>> own_;  // the few values between the pointed-to blocks
  std::vector<std::span<const double>> pieces_;
};

}  // namespace rfem
