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
// The sweep file is read beside the case reader (cases/sweep_file.hpp); the index, a point's record
// and the lock sit with the results files (results/sweep_index.hpp); the scheduling is here.
// The building blocks (read_sweep, run_point, finished_point, write_index) let any scheduler run
// the points: run_sweep's threads on one machine, the program's MPI ranks, a user's own pool. One
// sweep at a time writes an index and its runs (SweepLock): a second is refused before it touches
// anything.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "../cases/case_file.hpp"
#include "../cases/sweep_file.hpp"
#include "../results/sweep_index.hpp"
#include "../simulation/common.hpp"
#include "../solvers/run_status.hpp"

namespace rfem {

/// Reads a sweep file; `index` overrides [sweep] output (default: the sweep file's stem + ".h5" in
/// the current directory, runs in STEM.runs/ beside it). Checks everything before any run: the
/// file (CaseError "file:line: key: …"; `quantities` must name at least one), every generated case
/// and its quantities (CaseError "file: point k (key=value, …): …").
Sweep read_sweep(const std::string& path, const std::string& index = "");

/// Runs point k into its file (the file is replaced), the quantities recorded in it; threads:
/// the run's team (0: all). A failure is the row's status, never an exception (a bad value the
/// case reader refuses included).
SweepRow run_point(const Sweep& s, int k, const StopToken& stop, int threads = 1, const Warnings& warn = {});
/// One row per point, from their files where finished (finished_point; a failed one counts as
/// finished unless retry_failed); returns the points to run, longest expected first.
std::vector<int> plan_sweep(const Sweep& s, bool retry_failed, std::vector<SweepRow>& rows);
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
