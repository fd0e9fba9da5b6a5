#pragma once
// HDF5 results: one group per run with chunked, extendible datasets along time, flushed as the run
// goes, so a run that fails or is interrupted leaves a valid file with every completed output step
// and a `status` attribute saying why it stopped. Layout documented in README.md ("Results").
#include <hdf5.h>

#include <chrono>
#include <map>
#include <string>
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
  void attribute(const std::string& key, const std::string& value);
  void attribute(const std::string& key, double value);
  void flush();
  long samples() const { return rows_; }

 private:
  struct Series {
    hid_t dset = -1;
    int cols = 1;
  };
  void add_series(const std::string& name, int cols, const std::string& columns);
  void write_row(const std::string& name, long row, const double* data);
  ResultsFile& file_;
  const Model& model_;
  hid_t group_ = -1;
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

 private:
  std::string path_;
  hid_t file_ = -1;
};

/// Tip deflections in the paper's notation for the run's flexible link: u1 along y of {r} (in the
/// plane of joints 2 and 3 for the paper's manipulator), u2 along z, θ the torsion φ1 of rfe_n.
Eigen::Vector3d tip_deflection(const Model& model, const VecX& q);

/// Writes a string attribute on any HDF5 object.
void write_attribute(hid_t obj, const std::string& key, const std::string& value);
void write_attribute(hid_t obj, const std::string& key, double value);

}  // namespace rfem::app
