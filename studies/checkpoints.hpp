#pragma once
// What a run's checkpoint holds (results/writer.hpp stores it in the run's group): the integrator's
// state, the run's own summary so far (peaks, energy balance, validity, outputs, wall time) and the
// state of every observer that accumulates over a study (by its state_key), packed as doubles.
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "../solvers/integrator.hpp"

namespace rfem {

/// A packed state's blocks: their length, then their values.
void put_block(std::vector<double>& x, const std::vector<double>& block);
/// The block at x[i] (i moves past it); std::invalid_argument(`what`) if x ends before it does.
std::vector<double> take_block(const std::vector<double>& x, size_t& i, const std::string& what);

/// A packed run state (the layout RunState::unpack reads) as pieces in order: the integrator's q, v, a and
/// the observers' states are pointed to, not copied (a checkpoint of n rfes then needs no memory of
/// its own: the results file writes it piece by piece). Valid while what it points to is.
class PackedState {
 public:
  PackedState(const IntegratorState& integrator, const std::vector<double>& summary,
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

struct RunState {
  IntegratorState integrator;
  std::vector<double> summary;
  std::vector<std::pair<double, std::vector<double>>> observers;  ///< (key's hash, state)
  /// The state saved under `key`, or null.
  const std::vector<double>* find(const std::string& key) const;
  void add(const std::string& key, std::vector<double> state);
  /// Throws std::invalid_argument naming what does not fit (another version, another model).
  static RunState unpack(const std::vector<double>& x, int unknowns);
};

}  // namespace rfem
