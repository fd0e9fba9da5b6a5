// `rfem sweep` under mpirun: rank 0 hands out points one at a time to the ranks that ask (runs
// differ in cost by orders of magnitude: no static split), longest first, and alone writes the
// index; every other rank runs points into their own files (serial HDF5, one thread each) and
// reports each row. SIGINT/SIGTERM (mpirun forwards them to every rank) end the running points and
// the sweep with a valid index; a rank that dies takes the job down (OpenMPI), and a rerun redoes
// the points that did not finish.
#include <fmt/core.h>

#include <algorithm>

#include "commands.hpp"
#include "signals.hpp"
#include "rfem/studies/sweep.hpp"

#ifdef RFEM_HAVE_MPI
#define OMPI_SKIP_MPICXX 1  // the C API only (OpenMPI's C++ bindings need their own library)
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace rfem::app {

#ifndef RFEM_HAVE_MPI

int run_sweep_mpi(const SweepOptions&, bool, bool) {
  throw std::runtime_error("this rfem was built without MPI: run the sweep without mpirun (--jobs N), or rebuild with libopenmpi-dev");
}

#else

namespace {

enum Tag { kAsk = 1, kWork = 2 };

void send_text(const std::string& s, int to, int tag) {
  MPI_Send(s.data(), static_cast<int>(s.size()), MPI_CHAR, to, tag, MPI_COMM_WORLD);
}

std::string receive_text(int& from, int tag) {
  MPI_Status st;
  MPI_Probe(from, tag, MPI_COMM_WORLD, &st);
  int count = 0;
  MPI_Get_count(&st, MPI_CHAR, &count);
  std::string s(static_cast<size_t>(count), '\0');
  MPI_Recv(s.data(), count, MPI_CHAR, st.MPI_SOURCE, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  from = st.MPI_SOURCE;
  return s;
}

nlohmann::json row_json(int k, const SweepRow& r) {
  nlohmann::json v = nlohmann::json::array();
  for (double x : r.values) v.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json());
  return {{"point", k}, {"status", r.status}, {"wall_s", std::isfinite(r.wall_s) ? nlohmann::json(r.wall_s) : nlohmann::json()},
          {"t_reached", std::isfinite(r.t_reached) ? nlohmann::json(r.t_reached) : nlohmann::json()}, {"steps", r.steps},
          {"residual_evals", r.residual_evals}, {"values", v}};
}

SweepRow json_row(const nlohmann::json& j) {
  SweepRow r;
  auto num = [](const nlohmann::json& x) { return x.is_null() ? NAN : x.get<double>(); };
  r.status = j["status"].get<std::string>();
  r.wall_s = num(j["wall_s"]);
  r.t_reached = num(j["t_reached"]);
  r.steps = j["steps"].get<long>();
  r.residual_evals = j["residual_evals"].get<long>();
  for (const auto& x : j["values"]) r.values.push_back(num(x));
  return r;
}

// Rank 0: the points to run, one to each rank that asks, and the index after every report.
std::vector<SweepRow> coordinate(const Sweep& s, const SweepOptions& o, int ranks, const StopToken& stop, bool show) {
  std::vector<SweepRow> rows;
  const std::vector<int> todo = plan_sweep(s, o.retry_failed, rows);
  SweepProgress pr;
  pr.total = static_cast<int>(rows.size());
  for (const SweepRow& r : rows)
    if (r.status != "pending") ++(r.completed() ? pr.done : pr.failed);
  write_index(s, rows);
  size_t next = 0;
  int working = ranks - 1;  // ranks that have not been told to stop
  while (working > 0) {
    int from = MPI_ANY_SOURCE;
    const nlohmann::json msg = nlohmann::json::parse(receive_text(from, kAsk));
    if (msg.contains("point")) {
      const int k = msg["point"].get<int>();
      rows[static_cast<size_t>(k)] = json_row(msg);
      --pr.running;
      if (rows[static_cast<size_t>(k)].status != "interrupted") {
        ++(rows[static_cast<size_t>(k)].completed() ? pr.done : pr.failed);
        write_index(s, rows);
      }
      if (show) print_sweep_progress(pr);
    }
    const int k = !stop.requested() && next < todo.size() ? todo[next++] : -1;
    send_text(std::to_string(k), from, kWork);
    if (k < 0) --working;
    else ++pr.running;
  }
  write_index(s, rows);
  return rows;
}

// Any other rank: ask, run, report, until told to stop.
void work(const Sweep& s, const StopToken& stop) {
  std::string report = "{}";
  for (;;) {
    send_text(report, 0, kAsk);
    int from = 0;
    const int k = std::stoi(receive_text(from, kWork));
    if (k < 0) return;
    const SweepRow r = run_point(s, k, stop, 1, [k](const std::string& w) { print_warning(fmt::format("point {}: {}", k, w)); });
    report = row_json(k, r).dump();
  }
}

}  // namespace

int run_sweep_mpi(const SweepOptions& o, bool json, bool quiet) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  StopToken stop;
  int code = 0;
  {
    const SignalStop signals(stop);
    // Every rank reads and checks the sweep; only rank 0 speaks of a bad one.
    std::string error;
    Sweep s;
    try {
      s = read_sweep(o.path, o.output);
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (!error.empty()) {
      if (rank == 0) fmt::print(stderr, "rfem: error: {}\n", error);
      MPI_Finalize();
      return 2;
    }
    if (rank == 0) {
      const std::vector<SweepRow> rows = coordinate(s, o, ranks, stop, !quiet && !json);
      code = print_sweep(s, rows, stop, json, quiet);
    } else {
      work(s, stop);
    }
  }
  MPI_Finalize();
  return rank == 0 ? code : 0;
}

#endif

}  // namespace rfem::app
