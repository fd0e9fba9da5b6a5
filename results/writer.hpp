#pragma once
// HDF5 results files: one group per run with chunked, extendible datasets along time (the layout
// of results/layout.hpp), flushed as the run goes, so a run that fails or is interrupted leaves a
// valid file with every completed output step and a `status` saying why it stopped. While a run
// writes, the file is in HDF5's single-writer / multiple-reader (SWMR) mode: h5py
// (`h5py.File(path, "r", swmr=True)`) can watch it, and the run's `status_now` dataset says
// `running`. SWMR allows no new objects or attributes, so what a run learns at its end is written
// when SWMR ends (the file is closed and reopened). Every HDF5 call is checked: a failure throws
// ResultsError naming the file. Layout documented in README.md ("Results").
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "../solvers/integrator.hpp"
#include "../solvers/refinement.hpp"
#include "errors.hpp"
#include "layout.hpp"
#include "reader.hpp"

namespace rfem {

/// File attributes that let a results file describe its own run.
struct FileDescription {
  std::string command_line;    ///< how the file was made (the program's arguments, or a script's note)
  std::string case_path;
  std::string case_text;       ///< the case file as read
  std::string case_effective;  ///< the case after the overrides, as TOML
  std::string overrides;       ///< the --set values, one per line
  std::string procedure;       ///< single | paper | refine
  long n = -1;                 ///< rfes of every run in the file (−1: not one n, as in a refinement)
  long n_option = -1;          ///< the n the runs were asked for (0: the case's own; −1: not one run's)
  long threads = 0;            ///< the largest thread team of the runs
  /// A run stepped by its caller (rfem::Simulation, a controller in the loop): who drove it. Its
  /// inputs came from outside the case, so `rfem run --resume` refuses it ("": the case's own run).
  std::string driven_by;
};

/// What a run group records about the run besides its series.
struct RunDescription {
  IntegratorOptions options;
  std::vector<std::string> inputs;  ///< per joint: motion, torque or feedback
  int flexible_every = 0;           ///< store the rfe coordinates every k outputs (0: never)
  long threads = 0;
  /// The case's [[sensors]] (time first): the group's `sensors` table, a row per output
  /// (RunWriter::append_sensors); none if empty.
  std::vector<std::string> sensor_columns, sensor_units;
};

class RunWriter;

/// Opens an existing results file to continue its runs (ResultsWriter's resuming constructor).
struct Reopen {};

/// A results file, created (or truncated) on construction. Movable, not copyable; closing never
/// throws from the destructor (close() reports a failure).
class ResultsWriter {
 public:
  ResultsWriter(const std::string& path, const FileDescription& description);
  /// An existing results file, for resume_run (also a file a killed run left: its SWMR flags are
  /// cleared). Refused like a new file if another rfem run writes it.
  ResultsWriter(const std::string& path, Reopen);
  ~ResultsWriter();
  ResultsWriter(ResultsWriter&&) noexcept;
  ResultsWriter& operator=(ResultsWriter&&) noexcept;
  ResultsWriter(const ResultsWriter&) = delete;
  ResultsWriter& operator=(const ResultsWriter&) = delete;
  const std::string& path() const;
  /// A new run group `name` ("run", "n12/kinematic"): its series are written by the returned
  /// writer, which must be finished before the next run begins.
  std::unique_ptr<RunWriter> begin_run(const std::string& name, std::shared_ptr<const Model> model,
                                       const RunDescription& description);
  /// Run group `name` reopened at checkpoint `from`: its series cut back to the rows the checkpoint
  /// covers, the run `running` again; the returned writer goes on from there. The group must have
  /// been written by begin_run with the same model and description.
  std::unique_ptr<RunWriter> resume_run(const std::string& name, std::shared_ptr<const Model> model,
                                        const RunDescription& description, const Checkpoint& from);
  /// The group `refine`: n and, per quantity, refine/q<k> with value, change, order, richardson
  /// and its assessment; the first quantity's datasets also directly in `refine`. A series over
  /// modes (`modes_at_n` > 0, its n an attribute) has a dataset `modes` (0: the full model) for n.
  void write_refinement(const std::vector<std::string>& quantities, const std::vector<int>& ns,
                        const std::vector<Refinement>& tables, const RunStatus& status, int modes_at_n = 0);
  /// A table that does not grow (rows × columns, row-major), with its columns, units and
  /// description; its groups are created as needed ("modes/shapes").
  void write_table(const std::string& name, const Table& table, const std::vector<std::string>& columns,
                   const std::vector<std::string>& units, const std::string& description);
  /// String attributes of an object ("/", "modes").
  void write_attribute(const std::string& object, const std::string& key, const std::string& value);
  void write_attribute(const std::string& object, const std::string& key, const std::vector<std::string>& values);
  void write_attribute(const std::string& object, const std::string& key, double value);
  /// A link `name` to `object` in another HDF5 file (`file` relative to this one's directory or
  /// absolute): h5py follows it as a group of this file.
  void write_external_link(const std::string& name, const std::string& file, const std::string& object);
  /// Flushes and closes the file; throws ResultsError if HDF5 cannot.
  void close();

  struct File;  // (shared with the run writers)
 private:
  std::shared_ptr<File> file_;
};

/// One run's group. Appends output samples; finish() writes how the run ended. Made by
/// ResultsWriter::begin_run; shares the file with it.
class RunWriter {
 public:
  ~RunWriter();  ///< closes the group (the status stays `running` unless finished)
  RunWriter(const RunWriter&) = delete;
  RunWriter& operator=(const RunWriter&) = delete;
  void append(const OutputSample& s);
  /// The sensors' row of the output just appended (time first; RunDescription::sensor_columns).
  void append_sensors(const std::vector<double>& row);
  /// Records a checkpoint covering every row appended so far (flushed first), in the older slot.
  /// The state comes in pieces (simulation/state.hpp), written one after the other: no copy of it.
  void checkpoint(const std::vector<std::span<const double>>& pieces);
  /// Writes the status, the integrator's statistics, the wall time and any warnings about the
  /// solution (attribute `warnings`, one per line), and leaves SWMR mode.
  void finish(const RunOutcome& outcome, double wall_s, const std::vector<std::string>& warnings = {});
  long samples() const;

  struct Impl;
  explicit RunWriter(std::unique_ptr<Impl> impl);

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace rfem
