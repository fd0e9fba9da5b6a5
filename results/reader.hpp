#pragma once
// Reading a results file back: the series of a run group and its string attributes, every shape
// checked (a file that rfem did not write, or another program changed, gives ResultsError, never a
// read past an array).
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "errors.hpp"

namespace rfem {

/// A 2-D table of doubles, row-major.
struct Table {
  long rows = 0, cols = 0;
  std::vector<double> data;
  double at(long r, long c) const { return data[static_cast<size_t>(r * cols + c)]; }
  /// Column c as a vector.
  std::vector<double> column(long c) const;
};

class ResultsReader {
 public:
  /// Opens a results file read-only (also while a run writes it: SWMR). Throws ResultsError
  /// ("PATH: not a readable HDF5 results file").
  explicit ResultsReader(const std::string& path);
  ~ResultsReader();
  ResultsReader(ResultsReader&&) noexcept;
  ResultsReader& operator=(ResultsReader&&) noexcept;
  ResultsReader(const ResultsReader&) = delete;
  ResultsReader& operator=(const ResultsReader&) = delete;
  const std::string& path() const;
  /// Whether `object` ("force", "force/joint_tau") exists.
  bool has(const std::string& object) const;
  /// The 2-D float64 dataset `object`; throws ResultsError if it is missing or not 2-D.
  Table table(const std::string& object) const;
  /// Rows first … first + count − 1 of it (a damaged chunk elsewhere does not matter); throws like table().
  Table rows(const std::string& object, long first, long count) const;
  /// Rows and columns of the 2-D dataset `object`, without reading it; throws like table().
  std::pair<long, long> shape(const std::string& object) const;
  /// The names of the members of group `group` ("/" for the file), in name order.
  std::vector<std::string> children(const std::string& group) const;
  /// The string attribute `key` of `object` ("/" for the file); `fallback` if there is none.
  std::string attribute(const std::string& object, const std::string& key, const std::string& fallback = "") const;
  /// A numeric attribute (`fallback` if missing or not a number).
  double number(const std::string& object, const std::string& key, double fallback = NAN) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A run's last checkpoint in its group (dataset `checkpoint`): the output rows and flexible rows it
/// covers and the state to resume from (simulation/state.hpp packs it). Two slots written in
/// turn, each with a checksum, so a run killed while writing one still has the other.
struct Checkpoint {
  long rows = 0, flexible_rows = 0;
  long sequence = 0;  ///< how many checkpoints the run wrote before this one
  std::vector<double> state;
};
/// The newest intact checkpoint of run group `run`, if it has one.
std::optional<Checkpoint> read_checkpoint(const ResultsReader& file, const std::string& run);

}  // namespace rfem
