#pragma once
// Parameter sweeps (`rfem sweep SWEEP.toml`, rfem.sweep): a base case and parameters over the
// paths of `--set`, crossed (grid) or zipped, each point one run of the case's procedure into its
// own results file, the quantities of `rfem refine` recorded per run, and one index file.
//
// The run files are the record: a point whose file holds a completed run of the same overrides
// (with its quantities) is not run again; one interrupted, killed or missing is; a failed one
// keeps its reason (and is retried on request). The index — parameters, quantities, statistics,
// each run's status and an external link to its file — is rebuilt from them after every run,
// written whole (a temporary file renamed into place), so it is valid at any moment.
//
// The building blocks (read_sweep, run_point, finished_point, write_index) let any scheduler run
// the points: run_sweep's threads on one machine, the program's MPI ranks, a user's own pool. One
// sweep at a time writes an index and its runs (SweepLock): a second is refused before it touches
// anything.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rfem/cases/case_file.hpp"
#include "rfem/solvers/run_status.hpp"
#include "rfem/studies/common.hpp"

namespace rfem {

struct SweepPoint {
  std::vector<std::string> overrides;  ///< "key=value" of its parameters, after the sweep's `set`
  std::vector<double> values;          ///< its parameters' values (NaN where not a number)
  std::string file;                    ///< its results file
  double cost = 0.0;                   ///< expected cost, for longest-first order: rfes × t_end
};

struct Sweep {
  std::string path, text;          ///< the sweep file and its text
  std::string case_path;           ///< the base case
  std::vector<std::string> set;    ///< overrides of every point ([sweep] set)
  std::vector<std::string> parameters;  ///< the swept keys (`n`: rfes in all, as --n)
  std::vector<std::string> quantities;  ///< as rfem refine's --quantity
  bool zip = false;                ///< points: parameters zipped (else every combination)
  std::string index;               ///< the index file
  std::string directory;           ///< the run files' directory
  double checkpoint = 0.0;         ///< wall time between a run's checkpoints [s] ([sweep] checkpoint, 0: none)
  std::vector<SweepPoint> points;
};

/// Reads a sweep file; `index` overrides [sweep] output (default: the sweep file's stem + ".h5" in
/// the current directory, runs in STEM.runs/ beside it). Checks everything before any run: the
/// file (CaseError "file:line: key: …"; `quantities` must name at least one), every generated case
/// and its quantities (CaseError "file: point k (key=value, …): …").
Sweep read_sweep(const std::string& path, const std::string& index = "");

/// What a point's run gave (or why it did not).
struct SweepRow {
  std::optional<RunStatus> status;  ///< how its run ended; none: pending (not run)
  double wall_s = NAN, t_reached = NAN;
  long steps = 0, residual_evals = 0;
  std::vector<double> values;      ///< per quantity (NaN until completed)
  bool pending() const { return !status; }
  bool completed() const { return status && status->is_completed(); }
  bool interrupted() const { return status && status->kind == RunStatus::Kind::Interrupted; }
  /// As the index and the run files hold it: "pending" or the status's text.
  std::string status_text() const { return status ? status->to_string() : std::string("pending"); }
  /// The inverse of status_text().
  static std::optional<RunStatus> parse_status(const std::string& text) {
    return text == "pending" ? std::nullopt : std::optional<RunStatus>(RunStatus::parse(text));
  }
};

/// Runs point k into its file (the file is replaced), the quantities recorded in it; threads:
/// the run's team (0: all). A failure is the row's status, never an exception (a bad value the
/// case reader refuses included).
SweepRow run_point(const Sweep& s, int k, const StopToken& stop, int threads = 1, const Warnings& warn = {});
/// Point k's row from its file if the file holds a finished run (completed or failed) of this
/// point's overrides; nullopt if it must run (missing, interrupted, killed, another point's).
std::optional<SweepRow> finished_point(const Sweep& s, int k);
/// One row per point, from their files where finished (finished_point; a failed one counts as
/// finished unless retry_failed); returns the points to run, longest expected first.
std::vector<int> plan_sweep(const Sweep& s, bool retry_failed, std::vector<SweepRow>& rows);
/// Writes the index (whole into INDEX.tmp, then renamed into place; the .tmp removed if that fails).
void write_index(const Sweep& s, const std::vector<SweepRow>& rows);

/// The right to write a sweep's index and run files, held while it lives: an exclusive lock
/// (flock) on STEM.runs/sweep.lock, taken before anything is written, released when the process
/// ends however it ends. Throws ResultsError naming the index if another sweep (any process, this
/// one included) holds it, if the runs' folder cannot be created there (a read-only folder), or if
/// the index is not a file.
class SweepLock {
 public:
  explicit SweepLock(const Sweep& s);
  ~SweepLock();
  SweepLock(const SweepLock&) = delete;
  SweepLock& operator=(const SweepLock&) = delete;

 private:
  int fd_ = -1;
};

struct SweepProgress {
  int done = 0, failed = 0, running = 0, total = 0, skipped = 0;  ///< (interrupted points count in none)
  double elapsed_s = 0, left_s = NAN;  ///< time left: the remaining cost at the rate so far
};

struct SweepRequest {
  int jobs = 0;                   ///< runs at once, one thread each (0: the cores)
  bool retry_failed = false;      ///< run failed points again
  StopToken stop;                 ///< ends the running points and the sweep; the index stays valid
  std::function<void(const SweepProgress&)> progress;  ///< after every point (from the worker that ran it, one call at a time)
  Warnings warn;
};

/// Runs every point that must run, longest first, `jobs` at a time; returns all rows (the index
/// written after each point). Takes the sweep's SweepLock first (ResultsError if it cannot).
std::vector<SweepRow> run_sweep(const Sweep& s, const SweepRequest& request);
/// The same with the lock the caller holds (a program that tells a refusal from a failure).
std::vector<SweepRow> run_sweep(const Sweep& s, const SweepRequest& request, const SweepLock& held);

}  // namespace rfem
