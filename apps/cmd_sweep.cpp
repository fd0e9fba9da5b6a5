// `rfem sweep SWEEP.toml`: a parameter sweep on this machine (--jobs runs at once) or, started by
// mpirun, across its ranks (apps/sweep_mpi.cpp). Prints one progress line, then the table.
#include <fmt/core.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>

#include "commands.hpp"
#include "signals.hpp"
#include "../results/errors.hpp"
#include "../studies/sweep.hpp"

namespace rfem::app {

namespace {

std::string duration(double s) {
  if (!std::isfinite(s)) return "?";
  if (s < 90) return fmt::format("{:.0f} s", s);
  if (s < 5400) return fmt::format("{:.0f} min", s / 60);
  return fmt::format("{:.1f} h", s / 3600);
}

SweepLock lock_sweep(const Sweep& s) {
  try {
    return SweepLock(s);
  } catch (const ResultsError& e) {  // refused before anything was written: exit 2, as rfem run's unwritable output
    throw CaseError(e.what());
  }
}

}  // namespace

void print_sweep_progress(const SweepProgress& p) {
  if (!isatty(fileno(stderr))) return;
  fmt::print(stderr, "\rsweep: {}/{} done, {} failed, {} running, {} left   ", p.done + p.failed, p.total, p.failed, p.running,
             duration(p.left_s));
  std::fflush(stderr);
}

int print_sweep(const Sweep& s, const std::vector<SweepRow>& rows, const StopToken& stop, bool json, bool quiet) {
  if (isatty(fileno(stderr))) fmt::print(stderr, "\r{:80}\r", "");
  int done = 0, failed = 0, interrupted = 0;
  for (const SweepRow& r : rows) {
    if (r.interrupted()) ++interrupted;
    else if (!r.pending()) ++(r.completed() ? done : failed);
  }
  if (json) {
    nlohmann::json js = nlohmann::json::array();
    for (size_t k = 0; k < rows.size(); ++k) {
      nlohmann::json q = nlohmann::json::object();
      for (size_t i = 0; i < s.quantities.size(); ++i) q[s.quantities[i]] = std::isfinite(rows[k].values[i]) ? nlohmann::json(rows[k].values[i]) : nlohmann::json();
      js.push_back({{"point", k}, {"overrides", s.points[k].overrides}, {"status", rows[k].status_text()}, {"quantities", q},
                    {"wall_s", std::isfinite(rows[k].wall_s) ? nlohmann::json(rows[k].wall_s) : nlohmann::json()},
                    {"steps", rows[k].steps}, {"file", s.points[k].file}});
    }
    print_json({{"command", "sweep"}, {"sweep", s.path}, {"index", s.index}, {"parameters", s.parameters},
                {"quantities", s.quantities}, {"points", js}});
  } else if (!quiet) {
    std::string head = fmt::format("{:>5}", "point");
    std::vector<size_t> pw, qw;
    for (const auto& p : s.parameters) pw.push_back(std::max<size_t>(p.size(), 8));
    for (const auto& q : s.quantities) qw.push_back(std::max<size_t>(q.size(), 16));
    for (size_t i = 0; i < pw.size(); ++i) head += fmt::format(" {:>{}}", s.parameters[i], pw[i]);
    for (size_t i = 0; i < qw.size(); ++i) head += fmt::format(" {:>{}}", s.quantities[i], qw[i]);
    fmt::print("{}  status\n", head);
    for (size_t k = 0; k < rows.size(); ++k) {
      std::string line = fmt::format("{:>5}", k);
      for (size_t i = 0; i < pw.size(); ++i) {
        const std::string& o = s.points[k].overrides[i];
        line += fmt::format(" {:>{}}", o.substr(o.find('=') + 1), pw[i]);
      }
      for (size_t i = 0; i < qw.size(); ++i) {
        const double v = rows[k].values[i];
        line += std::isfinite(v) ? fmt::format(" {:>{}.9e}", v, qw[i]) : fmt::format(" {:>{}}", "-", qw[i]);
      }
      fmt::print("{}  {}\n", line, rows[k].status_text());
    }
    fmt::print("{} of {} runs completed, {} failed{}; index {} (runs in {}/)\n", done, rows.size(), failed,
               interrupted > 0 ? fmt::format(", {} interrupted", interrupted) : "", s.index, s.directory);
  }
  if (stop.requested()) return 128 + std::max(stop.signal(), 2);
  return failed > 0 || interrupted > 0 ? 1 : 0;
}

int run_sweep_command(const SweepOptions& o, bool json, bool quiet) {
  // Started by mpirun (OpenMPI's, or a PMI launcher's) with more than one rank: the MPI transport.
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* world = std::getenv(var); world && std::atoi(world) > 1) return run_sweep_mpi(o, json, quiet);
  const Sweep s = read_sweep(o.path, o.output);  // every point checked before any run
  const SweepLock lock = lock_sweep(s);
  SweepRequest rq;
  rq.jobs = o.jobs;
  rq.retry_failed = o.retry_failed;
  rq.warn = print_warning;
  const bool show = !quiet && !json;
  if (show) rq.progress = print_sweep_progress;
  const SignalStop signals(rq.stop);
  const std::vector<SweepRow> rows = run_sweep(s, rq, lock);
  return print_sweep(s, rows, rq.stop, json, quiet);
}

}  // namespace rfem::app
