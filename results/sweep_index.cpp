#include "sweep_index.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "../core/check.hpp"
#include "errors.hpp"
#include "reader.hpp"
#include "writer.hpp"

namespace rfem {

namespace fs = std::filesystem;

std::optional<SweepRow> finished_point(const Sweep& s, int k) {
  RFEM_CHECK_INDEX(k, s.points.size(), "sweep point");
  const SweepPoint& p = s.points[static_cast<size_t>(k)];
  if (!fs::exists(p.file)) return std::nullopt;
  try {
    const ResultsReader in(p.file);
    const std::string status = in.attribute("/", "sweep_status");
    if (status.empty() || in.attribute("/", "sweep_overrides") != joined(p.overrides, "\n")) return std::nullopt;
    SweepRow row;
    row.status = RunStatus::parse(status);
    if (!row.completed() && row.status->kind != RunStatus::Kind::Failed) return std::nullopt;  // (only finished runs are kept)
    const Table st = in.table("sweep_statistics");
    row.wall_s = st.at(0, 0);
    row.t_reached = st.at(0, 1);
    row.steps = static_cast<long>(st.at(0, 2));
    row.residual_evals = static_cast<long>(st.at(0, 3));
    row.values.assign(s.quantities.size(), NAN);
    if (!s.quantities.empty()) {
      const Table v = in.table("sweep_values");
      if (static_cast<size_t>(v.cols) != s.quantities.size()) return std::nullopt;  // other quantities: run again
      row.values = v.data;
    }
    return row;
  } catch (const std::exception&) {
    return std::nullopt;  // a file a killed run left: run again
  }
}

void write_index(const Sweep& s, const std::vector<SweepRow>& rows) {
  if (rows.size() != s.points.size()) throw std::invalid_argument("write_index: one row per point");
  const long R = static_cast<long>(rows.size()), P = static_cast<long>(s.parameters.size()), Q = static_cast<long>(s.quantities.size());
  if (!fs::path(s.index).parent_path().empty()) fs::create_directories(fs::path(s.index).parent_path());
  const std::string tmp = s.index + ".tmp";
  try {
    FileDescription d;
    d.command_line = "rfem sweep " + s.path;
    d.case_path = s.case_path;
    d.overrides = joined(s.set, "\n");
    d.procedure = "sweep";
    ResultsWriter w(tmp, d);
    Table par{R, P, {}}, qv{R, Q, {}}, st{R, 4, {}};
    std::vector<std::string> status, files, overrides;
    const fs::path home = fs::path(s.index).parent_path();
    for (long k = 0; k < R; ++k) {
      const SweepPoint& p = s.points[static_cast<size_t>(k)];
      const SweepRow& r = rows[static_cast<size_t>(k)];
      par.data.insert(par.data.end(), p.values.begin(), p.values.end());
      for (long q = 0; q < Q; ++q) qv.data.push_back(q < static_cast<long>(r.values.size()) ? r.values[static_cast<size_t>(q)] : NAN);
      st.data.insert(st.data.end(), {r.wall_s, r.t_reached, static_cast<double>(r.steps), static_cast<double>(r.residual_evals)});
      status.push_back(r.status_text());
      files.push_back(fs::path(p.file).lexically_relative(home.empty() ? fs::path(".") : home).string());
      overrides.push_back(joined(p.overrides, " "));
    }
    w.write_table("parameters", par, s.parameters, std::vector<std::string>(P, ""), "the swept values of each run (NaN: not a number, see overrides)");
    w.write_table("quantities", qv, s.quantities, std::vector<std::string>(Q, ""), "the quantities of each run (NaN: not completed)");
    w.write_table("statistics", st, {"wall_s", "t_reached", "steps", "residual_evals"}, {"s", "s", "1", "1"}, "each run's cost");
    w.write_attribute("/", "status", status);
    w.write_attribute("/", "files", files);
    w.write_attribute("/", "point_overrides", overrides);
    w.write_attribute("/", "sweep_path", s.path);
    w.write_attribute("/", "sweep_text", s.text);
    for (long k = 0; k < R; ++k)
      if (fs::exists(s.points[static_cast<size_t>(k)].file)) w.write_external_link(fmt::format("runs/{}", fs::path(files[static_cast<size_t>(k)]).stem().string()), files[static_cast<size_t>(k)], "/");
    w.close();
    std::error_code ec;
    fs::rename(tmp, s.index, ec);
    if (ec) throw ResultsError(s.index + ": cannot write the index: " + ec.message());
  } catch (...) {  // (the writer closed by now) no half-written index left beside the valid one
    std::error_code ec;
    if (fs::is_regular_file(tmp, ec)) fs::remove(tmp, ec);
    throw;
  }
}

SweepLock::SweepLock(const Sweep& s) {
  std::error_code ec;
  if (fs::exists(s.index, ec) && !fs::is_regular_file(s.index, ec)) throw ResultsError(s.index + ": is not a file (a directory?): give the index's file name");
  fs::create_directories(s.directory, ec);
  if (ec) throw ResultsError(s.index + ": cannot write the sweep's runs in " + s.directory + "/: " + ec.message());
  const std::string path = (fs::path(s.directory) / "sweep.lock").string();
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw ResultsError(s.index + ": cannot write the sweep's runs in " + s.directory + "/: " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    const int e = errno;
    ::close(fd_);
    if (e == EWOULDBLOCK)
      throw ResultsError(s.index + ": another sweep is writing this index and its runs (" + path + " is locked): wait for it to end");
    throw ResultsError(s.index + ": cannot lock " + path + ": " + std::strerror(e));
  }
}

SweepLock::~SweepLock() { ::close(fd_); }  // (closing releases the lock)

}  // namespace rfem
