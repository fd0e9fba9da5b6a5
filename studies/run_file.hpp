#pragma once
// The one path from a case to its results file: `rfem run`, Python's rfem.run and a sweep's points
// all run a case into a file through run_into_file (a resumed run goes through resume_case,
// studies/resume.hpp, into the file it continues); `rfem modes` and rfem.modes through
// modes_into_file, `rfem linearize` and rfem.linearize through linearize_into_file.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "../simulation/simulation.hpp"
#include "linearize.hpp"
#include "modes_study.hpp"
#include "refine.hpp"
#include "runs.hpp"

namespace rfem {

/// What run_into_file made: the model, every run's result, ParaView's views beside the file.
struct FileRuns {
  std::shared_ptr<const Model> model;
  std::vector<RunResult> runs;
  std::vector<std::string> views;
};

/// Runs the case's procedure into a new results file at `output`, in order: the case checked for
/// a run (check_runnable), its model with rq.n rfes and its inputs (bad inputs fail here, before the
/// file exists), the caller's `ready` (a cost check, a header line; it may throw to stop), the file
/// created (ResultsError for a path that cannot be created), the runs recorded into it before rq's own
/// observers see them, the file closed and ParaView's views written beside it (warnings through
/// rq.warn). `made_by` is the command line or call kept in the file. Every row a run computed is in
/// the file whatever its status.
/// A case whose [simulation] starts from a saved state (`state`): its one run as a stepped
/// simulation from that state (simulation/simulation.hpp), into `output` if not "", with rq's n,
/// threads, observers, series, warnings and stop token. CaseError naming simulation.state for a
/// file that is not a state, or the state of another model.
FileRuns run_from_state(const Case& cs, const RunRequest& rq, const std::string& output, const std::string& made_by);

FileRuns run_into_file(const Case& cs, RunRequest rq, const std::string& output, const std::string& made_by,
                       const std::function<void(const std::shared_ptr<const Model>&, const std::vector<JointInput>&)>& ready = {});

/// A refinement study into a new results file: every quantity and n checked first (CaseError),
/// the file created (ResultsError), every run recorded into it as it goes (groups "n12/run", …),
/// then the `refine` group with the tables, and the file closed. The rows of a study that stops
/// are kept.
RefineResult refine_into_file(const Case& cs, RefineRequest rq, const std::string& output, const std::string& made_by);

/// The case's modes (modes_study), written into a new results file at `output` (group `modes`,
/// write_modes) unless it is "". `threads` is the team kept in the file's description.
ModesStudy modes_into_file(const Case& cs, const ModesRequest& rq, const std::string& output, const std::string& made_by,
                           long threads);

/// The case's linear model (linearize), written into a new results file at `output` (group
/// `linear`, write_linear) unless it is ""; std::invalid_argument for a state of another model.
LinearModel linearize_into_file(const Case& cs, const LinearizeRequest& rq, const std::string& output, const std::string& made_by);

}  // namespace rfem
