#pragma once
// Running a case's [simulation] by its procedure: one run, or the paper's three (rigid inverse
// dynamics, kinematic input, force input with the rigid torques). Results come back in memory —
// status, statistics, peaks, the energy balance and, if kept, every series of the results layout
// (results/layout.hpp) — and stream to any observers while the runs go (an HDF5 file through
// simulation/recorders.hpp). A stop token ends a run cleanly within a step; progress goes to a
// callback; warnings are returned, never printed.
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
#include "../simulation/run_book.hpp"
#include "../solvers/integrator.hpp"

namespace rfem {

/// A case's procedure (one run, or the paper's three) under the same options.
struct RunRequest : RunOptions {
  std::vector<RunName> runs;  ///< which of the procedure's runs (empty: all; the paper's force run
                              ///< needs no other)
  std::string prefix;         ///< put before every run's name ("n12/")
  /// Continue a study (studies/resume.hpp): runs (by full name) that completed before and are not
  /// run again, and the checkpoints the others resume from.
  std::vector<std::string> done;
  std::map<std::string, Checkpoint> resume;
  /// With reduced links: estimate each run's reduction error (studies/reduction_error.hpp) by full
  /// and reduced runs at a coarse n after the runs complete, and warn through `warn` where it
  /// exceeds `reduction_allowed` of a peak (the target's relative accuracy, else the defaults' aim).
  bool reduction_error = true;
  double reduction_allowed = kDefaultsAim;
};

/// Runs the case's procedure on its model with n rfes (CaseError for a case without
/// [simulation] or joints, or bad inputs). A run that does not complete ends the procedure.
std::vector<RunResult> run_case(const Case& cs, const RunRequest& request);
/// The same on a given model with given inputs (one per joint).
std::vector<RunResult> run_case(const Case& cs, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs,
                                const RunRequest& request);

}  // namespace rfem
