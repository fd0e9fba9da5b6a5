#pragma once
// The rfem program's commands: each translates its options into a library call (studies/), prints
// the result and returns the exit code. Bad input throws CaseError (exit 2), solver failures
// std::runtime_error (exit 1).
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "../cases/case_file.hpp"
#include "../results/writer.hpp"
#include "../simulation/common.hpp"
#include "../solvers/inputs.hpp"
#include "../studies/accuracy.hpp"
#include "../studies/refine.hpp"
#include "../studies/runs.hpp"
#include "../studies/sweep.hpp"

namespace rfem::app {

/// Options every command shares.
struct Common {
  std::string command_line;            ///< the program's arguments, for the results file
  std::string case_path;
  std::vector<std::string> overrides;  ///< --set key.path=value
  int n = 0;                           ///< --n (0: the case's discretisation)
  bool json = false;
  bool quiet = false;    ///< no progress line and no summary (results only)
  bool verbose = false;  ///< log solver events
  int threads = 0;       ///< --threads (0: each run chooses)
  /// --accuracy (repeatable): a relative target ("1e-3") or QUANTITY=ERROR; replaces the case's [accuracy].
  std::vector<std::string> accuracy;
  int max_n = 0;         ///< --max-n (0: the target's, else kMaxTargetN)
  double max_time = 0.0; ///< --max-time [s] (0: the target's, else none)
};

struct ModesOptions {
  int count = 6;
  JointRate rate;  ///< --rate W --joint J
  /// `rfem modes --free`: joints that move with the modes (numbers from 1, names, or "base" for a
  /// free base's six); empty: every joint held.
  std::vector<std::string> free;
  std::string output;  ///< `rfem modes -o FILE`: the frequencies and shapes into HDF5
};

struct RefineOptions {
  std::vector<int> ns;                  ///< strictly increasing
  std::vector<std::string> quantities;  ///< evaluated from the same runs
  std::string output;                   ///< HDF5 file (default for dynamic quantities: CASE_refine.h5)
  bool integration_check = true;        ///< rerun the finest n at 100× tighter tolerances
  std::vector<int> modes;               ///< a series over link.modes at one n, against the full model
};

/// `rfem show`: the assembled tree of joints, links and bodies.
int run_show(const Common& c);
int run_static(const Common& c, const ModesOptions& o);
int run_modes(const Common& c, const ModesOptions& o);
struct RunOptions {
  std::string output;       ///< the results file
  std::string resume;       ///< --resume RESULTS.h5: continue that file's runs instead
  double checkpoint = 0.0;  ///< wall time between checkpoints [s] (0: none)
  bool no_reduction_check = false;  ///< --no-reduction-check: no companion runs for a reduced link's error
};
/// `rfem run`: time integration of the case's [simulation], results to an HDF5 file; or, with
/// --resume, the runs an interrupted or killed `rfem run` left, from their checkpoints.
int run_simulation(const Common& c, const RunOptions& o);
int run_refine(const Common& c, const RefineOptions& ro, const ModesOptions& o);
struct SweepOptions {
  std::string path;           ///< the sweep file
  std::string output;         ///< the index (default: [sweep] output, or the sweep's stem + .h5)
  int jobs = 0;               ///< runs at once on this machine (0: the cores)
  bool retry_failed = false;  ///< run failed points again
};
/// `rfem sweep SWEEP.toml`: here with --jobs, or across MPI ranks when started by mpirun.
int run_sweep_command(const SweepOptions& o, bool json, bool quiet);
int run_sweep_mpi(const SweepOptions& o, bool json, bool quiet);
/// The sweep's progress line (stderr, on a terminal) and its table or JSON; the exit code.
void print_sweep_progress(const SweepProgress& p);
int print_sweep(const Sweep& s, const std::vector<SweepRow>& rows, const StopToken& stop, bool json, bool quiet);
struct LinearizeOptions {
  std::string output;     ///< -o LIN.h5
  std::string state;      ///< --state SAVED.h5: about a saved simulation state (default: the initial equilibrium)
  bool on_motion = false; ///< --on-motion: the state's own accelerations (default: at rest)
  bool dense = false;     ///< --dense: column by column (the reference; O(n²))
};
/// `rfem linearize CASE -o LIN.h5`: the linear model into HDF5 (studies/linearize.hpp).
int run_linearize(const Common& c, const LinearizeOptions& o);
/// `rfem plot RESULTS.h5 [-o DIR]`: PNG figures of a results or refinement file.
int run_plot(const std::string& results, const std::string& outdir, const std::string& format = "", bool paper_signs = false);

/// `rfem animate RESULTS.h5 …`: the arm moving, as MP4 or GIF (options passed to python3 -m rfem.animate).
int run_animate(const std::vector<std::string>& args);
/// `rfem bode LIN.h5 --input J --output Y [-o FILE]`: a linear model's Bode plot (python3 -m rfem.linear).
int run_bode(const std::vector<std::string>& args);
/// `rfem view RESULTS.h5 [--run R]`: XDMF files for ParaView beside the results file.
int run_view(const std::string& results, const std::vector<std::string>& runs);

void print_json(const nlohmann::json& j);
/// Prints "rfem: warning: …" on stderr.
void print_warning(const std::string& w);
/// One line on stderr; never throws (a broken stderr must not turn an error into an abort).
void print_line(const std::string& line) noexcept;
/// The case of the command line (--set applied), its plausibility warnings printed to stderr.
Case read_checked_case(const Common& c);
/// Refuses a run the machine's memory cannot hold (CaseError); before a run of kLargeRunRfes rfes
/// or more prints its memory and the timed cost of a step (unless quiet).
void check_run_cost(const Case& cs, std::shared_ptr<const Model> model, const std::vector<JointInput>& inputs, const Common& c);
/// A command's target: --accuracy (replacing the case's [accuracy]) and --max-n, else the case's
/// [accuracy] unless --n is given; none if neither (AccuracySpec::given()). CaseError for --n with
/// --accuracy, unless --n is where the ladder starts (`n_starts_ladder`: rfem refine).
AccuracySpec accuracy_target(const Case& cs, const Common& c, bool n_starts_ladder = false);
/// The ladder's lines on stderr (RefineRequest::on_n; none when quiet).
std::function<void(int, int, int)> ladder_lines(const AccuracySpec& spec, bool quiet);
/// The estimates as a table, and whether the target was met (stdout).
void print_accuracy(const AccuracyResult& a);
nlohmann::json accuracy_json(const AccuracyResult& a);
/// The largest thread team a run may use (--threads, else OpenMP's default).
int max_threads(const Common& c);

}  // namespace rfem::app
