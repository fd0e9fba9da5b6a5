#pragma once
// HDF5 results: one group per run with chunked, extendible datasets along time, flushed as the run
// goes, so a run that fails or is interrupted leaves a valid file with every completed output step
// and a `status` saying why it stopped. While a run writes, the file is in HDF5's single-writer /
// multiple-reader (SWMR) mode: h5py (`h5py.File(path, "r", swmr=True)`) can watch it, and the
// run's `status_now` dataset says `running`. SWMR allows no new objects or attributes, so the
// attributes a run learns at its end are queued and written when SWMR ends (the file is closed and
// reopened). Layout documented in README.md ("Results").
#include <hdf5.h>

#include <chrono>
#include <map>
#include <string>
#include <variant>
#include <vector>

#include "solvers/integrator.hpp"

namespace rfem::app {

class ResultsFile;

/// One run's group. Appends output samples; attributes describe the run.
class RunGroup {
 public:
  RunGroup(ResultsFile& file, const std::string& name, const Model& model, int flexible_every);
  ~RunGroup();
  RunGroup(const RunGroup&) = delete;
  RunGroup& operator=(const RunGroup&) = delete;
  void append(const OutputSample& s);
  /// Written now, or queued while the file is in SWMR mode.
  void attribute(const std::string& key, const std::string& value);
  void attribute(const std::string& key, double value);
  void attribute(const std::string& key, long value);
  /// The live status (a fixed-size string dataset, writable in SWMR mode).
  void status(const std::string& s);
  void flush();
  /// Closes the datasets and the group (before the file leaves SWMR mode).
  void close();
  long samples() const { return rows_; }

 private:
  struct Series {
    hid_t dset = -1;
    int cols = 1;
  };
  void add_series(const std::string& name, const std::vector<std::string>& columns, const std::vector<std::string>& units,
                  const std::string& description = "");
  void write_row(const std::string& name, long row, const double* data);
  ResultsFile& file_;
  const Model& model_;
  std::string name_;
  hid_t group_ = -1, status_ = -1;
  std::map<std::string, Series> series_;
  long rows_ = 0, flex_rows_ = 0;
  int flexible_every_;
  std::chrono::steady_clock::time_point last_flush_;
};

class ResultsFile {
 public:
  explicit ResultsFile(const std::string& path);  ///< creates (truncates) the file
  ~ResultsFile();
  ResultsFile(const ResultsFile&) = delete;
  ResultsFile& operator=(const ResultsFile&) = delete;
  hid_t id() const { return file_; }
  void attribute(const std::string& key, const std::string& value);
  void flush();
  const std::string& path() const { return path_; }
  /// Enters SWMR mode (every group and dataset of the run must exist by now).
  void begin_swmr();
  /// Leaves SWMR mode (all objects closed): closes and reopens the file, writes queued attributes.
  void end_swmr();
  bool swmr() const { return swmr_; }
  using Value = std::variant<std::string, double, long>;
  /// Attribute `key` of object `path`: written now, or at end_swmr() in SWMR mode.
  void attribute(const std::string& path, const std::string& key, const Value& value);

 private:
  std::string path_;
  hid_t file_ = -1;
  bool swmr_ = false;
  struct Pending {
    std::string path, key;
    Value value;
  };
  std::vector<Pending> pending_;
};

/// Tip deflections in the paper's notation for flexible link l: u1 along y of {r} (in the plane of
/// joints 2 and 3 for the paper's manipulator), u2 along z, θ the torsion φ1 of rfe_n.
Eigen::Vector3d tip_deflection(const Model& model, int l, const VecX& q);

/// Writes an attribute on any HDF5 object (strings as variable-length UTF-8).
void write_attribute(hid_t obj, const std::string& key, const std::string& value);
void write_attribute(hid_t obj, const std::string& key, const std::vector<std::string>& values);
void write_attribute(hid_t obj, const std::string& key, double value);
void write_attribute(hid_t obj, const std::string& key, long value);

}  // namespace rfem::app
