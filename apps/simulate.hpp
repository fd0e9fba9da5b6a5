#pragma once
// Running a case's [simulation]: its joint inputs, the single or paper procedure, one HDF5 group
// per run with its summary. Shared by `rfem run` and dynamic quantities of `rfem refine`.
#include <atomic>
#include <functional>

#include "apps/commands.hpp"
#include "apps/results_file.hpp"

namespace rfem::app {

/// Peaks over a run of one link's tip deflections (tip_deflection).
struct LinkPeaks {
  std::string name;
  double u1 = 0, u2 = 0, theta = 0;
};

struct RunSummary {
  std::string name, status;
  bool completed = false;
  double wall = 0, t_reached = 0, energy_drift = 0, energy_scale = 0;
  std::vector<LinkPeaks> peaks;  ///< per link (empty without links)
  IntegratorStats stats;
  long samples = 0;
};

/// Called at every output step of every run, with the run's group name (prefix included).
using Observer = std::function<void(const std::string& run, const Model& model, const OutputSample& s)>;

/// The joints' inputs of a case (reads tabulated files and earlier results; CaseError if bad).
std::vector<JointInput> joint_inputs(const Case& cs);

/// Force input reproducing the rigid manipulator's inverse dynamics of the given motion laws,
/// evaluated exactly at every time (the paper's step 2). `rigid` must outlive the inputs.
std::vector<JointInput> rigid_torque_inputs(const Model& rigid, const std::vector<JointInput>& laws);

/// Runs the case's procedure on `model`, writing groups `prefix + run name` into `file`.
/// `threads` > 0 fixes the kernels' team size (--threads); 0 lets each run choose by timing.
std::vector<RunSummary> simulate_case(const Case& cs, const Model& model, const std::vector<JointInput>& inputs,
                                      ResultsFile& file, const std::string& prefix, bool quiet,
                                      const Observer& observe = {}, int threads = 0);

/// Before a run of `model`: refuses (CaseError naming link.n) a run whose estimated memory
/// (solvers/integrator.hpp, estimate_run) exceeds the memory available now; from kLargeRunRfes
/// rfes on prints a note with the memory and the timed cost of a step (unless quiet).
void check_affordable(const Case& cs, const Model& model, const std::vector<JointInput>& inputs, int threads,
                      bool quiet);

/// File attributes that let a results file describe its own run: rfem_version, build,
/// command_line, case_path, case_text (the file as read), case_effective (after --set), overrides,
/// procedure, n (when fixed for the file), threads.
void describe_run(ResultsFile& file, const Case& cs, const Common& c, const std::string& procedure, int n = -1);

/// SIGINT/SIGTERM set the stop flag: runs end cleanly after the current step.
void install_signal_handlers();
std::atomic<int>& stop_flag();

}  // namespace rfem::app
