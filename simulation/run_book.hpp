#pragma once
// A run's record as its outputs arrive: the options every way of running shares (RunOptions), the
// observers that see it (RunObserver: results files, a study's quantities), what it returns
// (RunResult: status, statistics, peaks, the energy balance, series kept in memory, sensors) and
// the book that keeps it (RunBook), around a Simulation's stepper (simulation/simulation.hpp).
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "../cases/case_file.hpp"
#include "../results/layout.hpp"
#include "../results/reader.hpp"
#include "../solvers/integrator.hpp"
#include "common.hpp"

namespace rfem {

/// Peaks over a run of one link's tip deflections (tip_deflection: |u1|, |u2|, |θ|).
struct LinkPeaks {
  std::string name;
  double u1 = 0, u2 = 0, theta = 0;
};

/// A run's series kept in memory, in the layout of results/layout.hpp.
struct RunSeries {
  RunLayout layout;
  std::vector<std::vector<double>> data;      ///< per layout.series: rows × width, row-major
  std::vector<std::vector<double>> flexible;  ///< per layout.flexible
  long rows = 0, flexible_rows = 0;
  /// A table without copying it: its description, its first value (row-major) and its rows.
  struct View {
    const SeriesInfo* info = nullptr;
    const double* data = nullptr;
    long rows = 0;
  };
  /// The table `name`: a series, a flexible series, a constant, or an alias ("tip"). Throws
  /// std::out_of_range for an unknown name.
  View view(const std::string& name) const;
  /// A copy of it.
  Table table(const std::string& name) const;
  /// Every name table() knows.
  std::vector<std::string> names() const;
};

struct RunResult {
  std::string name;  ///< its group: the request's prefix and "run", "rigid", "kinematic" or "force"
  RunStatus status;
  double wall_s = 0, t_reached = 0;
  IntegratorStats stats;
  long samples = 0;                     ///< output steps delivered
  std::vector<LinkPeaks> peaks;         ///< per link (empty without links)
  /// A run of reduced links: its peaks' estimated reduction error per link, signed (reduced − full
  /// peaks, both run at n = reduction_n; studies/reduction_error.hpp). Empty with reduction_n = 0:
  /// no estimate (no reduced link, not asked for, or the run did not complete).
  std::vector<LinkPeaks> reduction_error;
  int reduction_n = 0;
  /// max |balance(t) − balance(0)| with balance = T + V + dissipated − input work [J], and the
  /// largest of T, |V_e|, |input work| for scale.
  double energy_drift = 0, energy_scale = 0;
  /// Where the solution left the range the model is built on (simulation/validity.hpp), one line each.
  std::vector<std::string> warnings;
  std::shared_ptr<const Model> model;   ///< the model it ran (rigidified for `rigid`)
  std::shared_ptr<RunSeries> series;    ///< null unless the request keeps series
  /// The case's [[sensors]] as measured at every output (noise and resolution included; the file's
  /// `sensors` table): rows × columns, empty without sensors.
  Table sensors;
  std::vector<std::string> sensor_columns, sensor_units;
  bool completed() const { return status.is_completed(); }
};

/// What an observer learns when a run starts.
struct RunInfo {
  std::string name;
  std::shared_ptr<const Model> model;
  IntegratorOptions options;
  std::vector<std::string> inputs;  ///< per joint: motion, torque or feedback
  int flexible_every = 0;
  long threads = 0;                 ///< the largest team the run may use
  /// The checkpoint the run resumes from (its rows before it kept; null: from t = 0).
  const Checkpoint* resume = nullptr;
  /// The case's [[sensors]]: the columns of the row measured() gets at every output (time first),
  /// and their units; empty without sensors.
  std::vector<std::string> sensor_columns, sensor_units;
};

/// Sees every run of a study as it goes. A throwing sample() ends that run as failed with the
/// message (the samples before it stay delivered); a throwing begin() or end() ends the study.
class PackedState;

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  virtual void begin(const RunInfo&) {}
  virtual void sample(const OutputSample&) {}
  /// The sensors as measured at the output just sampled (time first; RunInfo::sensor_columns):
  /// called after sample() when the case has [[sensors]].
  virtual void measured(const std::vector<double>& /*row*/) {}
  virtual void end(const RunResult&) {}
  /// A checkpoint of the run (RunRequest::checkpoint_interval) after the samples so far: `state`
  /// is everything a resumed run needs (simulation/state.hpp); the observer that keeps the
  /// results file stores it (Hdf5Recorder).
  /// `state.joined()` is the packed vector; its pieces (simulation/state.hpp) point into the
  /// run, so an observer that stores them one by one needs no copy of the state.
  virtual void checkpoint(const PackedState& /*state*/) {}
  /// An observer that accumulates (over the study's runs) names its state here, gives it to every
  /// checkpoint and gets it back when a run resumes; "" for none.
  virtual std::string state_key() const { return {}; }
  virtual std::vector<double> save() const { return {}; }
  virtual void restore(const std::vector<double>& /*state*/) {}
};

/// Where a run is, for a progress display.
struct Progress {
  std::string run;
  double t = 0, t_end = 0;
  long steps = 0;
};

/// The default wall time between checkpoints [s]: a killed run loses at most this much; writing
/// the state (3 numbers per unknown) costs well under 1 % of it (bench/checkpoint_bench.py).
inline constexpr double kCheckpointInterval = 5.0;

/// How a run goes, one meaning for every way of running (rfem run, a study's runs, a simulation a
/// caller steps, Python): the discretisation, the thread team, what is kept and who hears of it.
struct RunOptions {
  int n = 0;                  ///< rfes in all links (0: the case's own discretisation)
  /// The kernels' team (0: each run times one thread against the largest team and keeps the
  /// faster, solvers/thread_governor.hpp).
  int threads = 0;
  bool keep_series = true;    ///< keep every series in memory (RunResult::series)
  /// request() ends the current run within a step (interrupted), and a study's later runs.
  StopToken stop;
  /// Called on the integrating thread at most every progress_interval seconds, and once at the end
  /// of every run that got past t = 0 (where it ended), however short. A callback that throws fails
  /// the run with its message.
  std::function<void(const Progress&)> progress;
  double progress_interval = 0.2;
  std::vector<RunObserver*> observers;  ///< the caller keeps them alive for the call
  Warnings warn;
  /// Wall time between a run's checkpoints [s] (0: none): written by the observers' checkpoint()
  /// (a results file's run group), resumed from with RunRequest::resume. A run whose inputs come
  /// from its caller (SimulationOptions::driven_by) keeps none: it cannot go on without the caller.
  double checkpoint_interval = kCheckpointInterval;
};

struct RunState;
struct SimulationState;
class ValidityMonitor;
class SensorBank;

/// The bookkeeping of one run as its outputs arrive — the observers, the series kept in memory,
/// peaks, the energy balance's drift, the validity warnings, checkpoints of all that, the final
/// progress report: what a Simulation (simulation/simulation.hpp) does around its stepper. The
/// options (observers, callbacks) outlive the book.
class RunBook {
 public:
  /// Tells the observers that the run begins; resuming (`checkpoint` and its unpacked `resumed`),
  /// restores the run's summary and the observers' state (std::invalid_argument for another model's).
  RunBook(std::string name, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs, const Case& cs,
          const RunOptions& rq, const IntegratorOptions& o, const Checkpoint* checkpoint = nullptr,
          const RunState* resumed = nullptr);
  ~RunBook();
  RunBook(const RunBook&) = delete;
  RunBook& operator=(const RunBook&) = delete;
  /// An output step: to the observers and the books (a throwing observer's message fails the run).
  void sample(const OutputSample& x);
  /// A checkpoint: the simulation's state with the book's and the observers' states, handed to the
  /// observers (the results file keeps it).
  void checkpoint(const SimulationState& st);
  /// Ends the run with the integrator's outcome: the result, also given to the observers.
  RunResult end(RunOutcome r);
  /// The result so far (status Running).
  const RunResult& result() const { return s_; }
  /// Where the recorded sensors' random streams are (SensorBank::save) for a state taken at time t:
  /// before the row at t if one was recorded there (a simulation started from the state records that
  /// row again, with the same noise), else now. Empty without sensors.
  std::vector<double> sensor_streams(double t) const;
  /// Sets them (a simulation started from a state or resumed); std::invalid_argument for another
  /// case's.
  void restore_sensor_streams(const std::vector<double>& x);
  /// Draws the noise of one row without reading it (a run resumed at a row it recorded: the state
  /// holds the streams before it).
  void skip_sensor_row();

 private:
  double wall() const;
  const RunOptions& rq_;
  IntegratorOptions o_;
  std::shared_ptr<const Model> model_;
  RunResult s_;
  std::unique_ptr<ValidityMonitor> validity_;
  std::unique_ptr<SensorBank> sensors_;  // null without [[sensors]]
  std::vector<std::vector<double>> rows_;
  std::vector<double> sensor_row_, streams_before_;  // the last sensors' row; the streams before it
  double sensor_t_ = NAN;                             // its time
  double balance0_ = NAN, wall_before_ = 0.0;
  std::chrono::steady_clock::time_point t0_;
};

/// CaseError unless the case can be run: a [simulation] table (a case without joints runs clamped).
void check_runnable(const Case& cs);

}  // namespace rfem
