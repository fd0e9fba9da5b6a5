#pragma once
// Observers that record a study's runs: into an HDF5 results file (one group per run, written as
// the run goes: results/writer.hpp).
#include <memory>

#include "../results/writer.hpp"
#include "run_book.hpp"

namespace rfem {

/// Writes every run it observes into `file` (which the caller keeps alive). A write that fails
/// (a full disk) ends the run as failed with the writer's message.
class Hdf5Recorder : public RunObserver {
 public:
  explicit Hdf5Recorder(ResultsWriter& file) : file_(file) {}
  void begin(const RunInfo& info) override;
  void sample(const OutputSample& s) override;
  void measured(const std::vector<double>& row) override;
  void end(const RunResult& r) override;
  void checkpoint(const PackedState& state) override;  // piece by piece into the file
  /// Output steps written of the current (or last) run.
  long samples() const { return run_ ? run_->samples() : 0; }

 private:
  ResultsWriter& file_;
  std::unique_ptr<RunWriter> run_;
};

/// ParaView's view (results/xdmf.hpp) of a results file just written for the case, when its runs
/// stored their poses (simulation.store_flexible_every > 0 and rfes); returns the files written.
/// A view that cannot be written is a warning, not an error: the results stand without it.
std::vector<std::string> write_views(const Case& cs, const Model& model, const std::string& results, const Warnings& warn);

/// The attributes that let a results file describe its study: the case as read and after its
/// overrides, how the file was made, the procedure ("single", "paper", "refine"), n (−1: several),
/// the threads; the n the runs were asked for (0: the case's own; −1 for a refinement), which lets
/// `--resume` build the same model.
FileDescription describe(const Case& cs, const std::string& command_line, const std::string& procedure, long n,
                         long threads, long n_option = -1);

}  // namespace rfem
