#pragma once
// A sweep file (`rfem sweep SWEEP.toml`, docs/commands.md): a base case and parameters over the
// paths of `--set`, crossed (grid) or zipped, read into its points (their overrides, values and
// files) beside the case reader. What the points' runs would refuse (their cases, quantities) is
// checked by studies/sweep.hpp's read_sweep.
#include <string>
#include <vector>

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

/// Reads the sweep file's [sweep] and [parameters] tables into its points; `index` overrides
/// [sweep] output (default: the sweep file's stem + ".h5" in the current directory, runs in
/// STEM.runs/ beside it); `checkpoint` is [sweep] checkpoint's default. CaseError "file:line: key:
/// …" (`quantities` must name at least one).
Sweep read_sweep_file(const std::string& path, const std::string& index, double checkpoint);

/// Point k's rfes in all (its parameter `n`, as --n; 0: the case's own), its case overrides (the
/// sweep's `set`, then its parameters but n), and its name in messages ("point 3 (n=24, …)").
int sweep_point_n(const Sweep& s, int k);
std::vector<std::string> sweep_case_overrides(const Sweep& s, int k);
std::string sweep_point_name(const Sweep& s, int k);
/// The strings joined by `sep`.
std::string joined(const std::vector<std::string>& v, const char* sep);

}  // namespace rfem
