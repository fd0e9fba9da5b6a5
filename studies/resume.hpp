#pragma once
// Continuing a run that was interrupted or killed, from its results file: the file holds the case
// as it was run (its text and overrides), the n asked for, and in each run group its status and
// last checkpoint (results/writer.hpp). Completed runs are kept; the first one that did not
// complete goes on from its checkpoint (from t = 0 without one); the procedure's later runs follow.
// The same outputs as the uninterrupted run: bit for bit with ESDIRK and the same thread team,
// within the tolerances with BDF (IDA restarts at the checkpoint).
#include <map>
#include <string>
#include <vector>

#include "../simulation/state.hpp"
#include "runs.hpp"

namespace rfem {

struct ResumePlan {
  std::string path;                             ///< the results file
  Case cs;                                      ///< the case as it was run
  int n = 0;                                    ///< the n asked for (0: the case's own)
  std::vector<std::string> done;                ///< run groups that completed: kept
  std::map<std::string, Checkpoint> resume;     ///< the run that goes on from its checkpoint
  bool finished() const;                        ///< every run of the procedure completed
};

/// Reads what `results` needs to continue. CaseError naming the file for a file rfem cannot
/// continue: not a results file of `rfem run` / rfem.run, or written by a version that recorded no
/// n, or whose case no longer reads (a case file's relative paths — a URDF — are resolved from
/// the current directory as when it ran).
ResumePlan plan_resume(const std::string& results);

/// Runs what the plan has left into its results file (reopened; refused while another rfem
/// writes it), with the request's threads, observers, stop and progress (its runs, done and
/// resume are the plan's). Returns the runs run now (none if all had completed), with keep_series
/// their whole series (read back from the file). ParaView's views
/// are the caller's, as after run_case (write_views).
std::vector<RunResult> resume_case(const ResumePlan& plan, RunRequest request);

/// A single run's newest checkpoint (an interrupted or killed `rfem run`'s) as a simulation's
/// state, to start rfem.Simulation or a case (simulation.state) from: the same state format
/// (simulation/state.hpp), its model's signature from the file's case and n. CaseError naming the
/// file for a procedure of several runs, a run that completed or wrote no checkpoint.
SimulationState checkpoint_state(const std::string& results);
/// A state file (save_state) or, failing that, a single run's results file (checkpoint_state).
SimulationState read_state(const std::string& path);

}  // namespace rfem
