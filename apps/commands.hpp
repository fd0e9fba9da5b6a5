#pragma once
// The rfem program's commands. Each returns the process exit code; bad input throws CaseError
// (exit 2), solver failures throw std::runtime_error (exit 1).
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cases/case_file.hpp"

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
  int threads = 0;
};

struct ModesOptions {
  int count = 6;
  double rate = 0.0;  ///< --rate: steady rate of joint `joint` [rad/s or m/s]
  int joint = 1;      ///< 1-based
  bool rate_given = false;
  /// `rfem modes --free`: joints that move with the modes (numbers from 1, names, or "base" for a
  /// free base's six); empty: every joint held.
  std::vector<std::string> free;
};

/// `rfem static`: equilibrium with the joints held, or in the frame of a steady joint rate.
int run_static(const Common& c, const ModesOptions& o);
int run_modes(const Common& c, const ModesOptions& o);
/// `rfem run`: time integration of the case's [simulation], results to an HDF5 file.
int run_simulation(const Common& c, const std::string& output);
struct RefineOptions {
  std::vector<int> ns;                 ///< strictly increasing
  std::vector<std::string> quantities;  ///< evaluated from the same runs
  std::string output;                  ///< HDF5 file (default for dynamic quantities: CASE_refine.h5)
  bool integration_check = true;       ///< rerun the finest n at 100× tighter tolerances
};

/// `rfem refine`: quantities over a series of n, with observed orders, Richardson extrapolation
/// where the series can be trusted, and the integration error of the finest run; dynamic
/// quantities (and --output) write every run and the tables to one HDF5 file.
int run_refine(const Common& c, const RefineOptions& ro, const ModesOptions& o);

/// Joint values and rates of the case, with --rate applied.
void joint_state(const Case& cs, const ModesOptions& o, VecX& qb, VecX& vb);
/// Evaluates a named scalar quantity (see README: "tip:uz", "mode:1", "bending-y:2", …) at n rfes.
double evaluate_quantity(const Case& cs, int n, const std::string& quantity, const ModesOptions& o);

void print_json(const nlohmann::json& j);

/// The case of the command line (--set applied), its plausibility warnings printed to stderr.
Case read_checked_case(const Common& c);

/// `rfem plot RESULTS.h5 [-o DIR]`: PNG figures of a results or refinement file.
int run_plot(const std::string& results, const std::string& outdir);

}  // namespace rfem::app
