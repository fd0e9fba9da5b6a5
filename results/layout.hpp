#pragma once
// What a run records at every output step, as named tables (rows = output steps): the one home of
// the results layout, for the HDF5 files (results/writer.hpp) and the results kept in memory
// (studies/). Documented in README.md ("Results").
#include <string>
#include <utility>
#include <vector>

#include "../core/model.hpp"
#include "../solvers/equations.hpp"

namespace rfem {

struct SeriesInfo {
  std::string name;                          ///< "time", "joint_q", "links/NAME/tip", …
  std::vector<std::string> columns, units;   ///< one per column
  std::string description;
  int width() const { return static_cast<int>(columns.size()); }
};

struct RunLayout {
  /// A row at every output step ("time" first).
  std::vector<SeriesInfo> series;
  /// A row every `flexible_every` output steps ("flexible_time" first; empty if not stored).
  std::vector<SeriesInfo> flexible;
  int flexible_every = 0;
  /// Tables that do not change (links/NAME/rfe_centre), with their values (row-major).
  std::vector<std::pair<SeriesInfo, std::vector<double>>> constants;
  /// Other names of the last link's tables at the top level ("tip" → "links/NAME/tip"): the layout
  /// of a model with one link.
  std::vector<std::pair<std::string, std::string>> aliases;
  /// Index of a series by name in `series` (−1 if none).
  int find(const std::string& name) const;
};

/// The layout of a run of `model` that stores the rfe coordinates every `flexible_every` outputs
/// (0: never).
RunLayout run_layout(const Model& model, int flexible_every);

/// The rows of one output sample, row `i` for layout.series[i] (each the series' width).
void sample_rows(const Model& model, const RunLayout& layout, const OutputSample& s, std::vector<std::vector<double>>& rows);
/// The rows of layout.flexible for the same sample (call on every flexible_every-th output).
void flexible_rows(const Model& model, const RunLayout& layout, const OutputSample& s,
                   std::vector<std::vector<double>>& rows);

}  // namespace rfem
