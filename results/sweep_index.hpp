#pragma once
// A sweep's record with the results files (studies/sweep.hpp runs it): what a point's run gave,
// read back from its file, the index of every point written whole, and the lock that lets one
// sweep at a time write them.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "../cases/sweep_file.hpp"
#include "../solvers/run_status.hpp"

namespace rfem {

/// What a point's run gave (or why it did not).
struct SweepRow {
  std::optional<RunStatus> status;  ///< how its run ended; none: pending (not run)
  double wall_s = NAN, t_reached = NAN;
  long steps = 0, residual_evals = 0;
  std::vector<double> values;      ///< per quantity (NaN until completed)
  bool pending() const { return !status; }
  bool completed() const { return status && status->is_completed(); }
  bool interrupted() const { return status && status->kind == RunStatus::Kind::Interrupted; }
  /// As the index and the run files hold it: "pending" or the status's text.
  std::string status_text() const { return status ? status->to_string() : std::string("pending"); }
  /// The inverse of status_text().
  static std::optional<RunStatus> parse_status(const std::string& text) {
    return text == "pending" ? std::nullopt : std::optional<RunStatus>(RunStatus::parse(text));
  }
};

/// Point k's row from its file if the file holds a finished run (completed or failed) of this
/// point's overrides; nullopt if it must run (missing, interrupted, killed, another point's).
std::optional<SweepRow> finished_point(const Sweep& s, int k);
/// Writes the index (whole into INDEX.tmp, then renamed into place; the .tmp removed if that fails).
void write_index(const Sweep& s, const std::vector<SweepRow>& rows);

/// The right to write a sweep's index and run files, held while it lives: an exclusive lock
/// (flock) on STEM.runs/sweep.lock, taken before anything is written, released when the process
/// ends however it ends. Throws ResultsError naming the index if another sweep (any process, this
/// one included) holds it, if the runs' folder cannot be created there (a read-only folder), or if
/// the index is not a file.
class SweepLock {
 public:
  explicit SweepLock(const Sweep& s);
  ~SweepLock();
  SweepLock(const SweepLock&) = delete;
  SweepLock& operator=(const SweepLock&) = delete;

 private:
  int fd_ = -1;
};

}  // namespace rfem
