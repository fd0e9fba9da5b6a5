#pragma once
// The case's sensors ([[sensors]], cases/sensor_spec.hpp) evaluated on a state: what a controller
// sees (Snapshot::sensors) and what a run records (its `sensors` table). Noise and quantisation
// come from each sensor's own random stream, seeded by the case: the same readings on every run.
#include <random>
#include <string>
#include <vector>

#include "../cases/case_file.hpp"

namespace rfem {

class SensorBank {
 public:
  /// Resolves every sensor of the case against the model (joints, links, the sde of a strain gauge
  /// and its section). std::invalid_argument for a model that is not the case's.
  SensorBank(const Case& cs, const Model& model);
  bool empty() const { return sensors_.empty(); }
  size_t size() const { return sensors_.size(); }
  const SensorSpec& spec(size_t i) const { return sensors_[i].spec; }
  /// Values of sensor i (1 for a torque or a strain, 2 for an encoder, 3 for a tip, 6 for an IMU).
  int width(size_t i) const;
  /// Every value's column name ("NAME", or "NAME/q", "NAME/qd", "NAME/u1" …) and unit.
  std::vector<std::string> columns() const;
  std::vector<std::string> units() const;
  /// Every sensor's values at a state (full q, v, a and the joints' torques), appended to `out`:
  /// exact, or as measured (noise, then quantisation) from the random streams of `stream`
  /// (0: the controller's snapshots, 1: the recorded outputs), which advance.
  void read(const VecX& q, const VecX& v, const VecX& a, const VecX& tau, std::vector<double>& out, int stream = -1);
  /// Where the random streams are (per sensor and stream, the numbers drawn so far), and back: a
  /// resumed run or a simulation started from a state reads the same noise as the run it continues.
  /// restore throws std::invalid_argument for another bank's state.
  std::vector<double> save() const;
  void restore(const std::vector<double>& state);
  /// Advances the streams of `stream` as read() would, without reading (a row already recorded).
  void skip(int stream);

 private:
  // A random engine that counts its draws: its state is (seed, count).
  struct Stream {
    std::mt19937_64 engine;
    unsigned long long seed = 0, drawn = 0;
    using result_type = std::mt19937_64::result_type;
    static constexpr result_type min() { return std::mt19937_64::min(); }
    static constexpr result_type max() { return std::mt19937_64::max(); }
    result_type operator()() {
      ++drawn;
      return engine();
    }
  };
  struct Resolved {
    SensorSpec spec;
    int joint = -1, link = -1, sde = -1;
    double EI = 0.0;  // strain: the bending stiffness of the gauge's section [N m²]
    Stream random[2];
  };
  // A sensor's exact values x[0..count) as measured: noise from `stream`, then quantisation.
  static void measure(Resolved& r, double* x, size_t count, int stream);
  const Model& model_;
  std::vector<Resolved> sensors_;
};

}  // namespace rfem
