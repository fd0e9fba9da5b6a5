// `rfem sweep` under mpirun: rank 0 holds the sweep's lock, hands out points one at a time to the
// ranks that ask (runs differ in cost by orders of magnitude: no static split), longest first, and
// alone writes the index; every other rank runs points into their own files (serial HDF5, one
// thread each) and reports each row. SIGINT/SIGTERM end the sweep as on one machine, whichever rank
// gets them (mpirun forwards them to every rank; a batch system or a user may signal one): rank 0
// hands out no more points and tells the ranks still running one to stop it, the points end
// interrupted, the index stays valid, the exit code is 128 + the signal. A rank that dies takes the
// job down (OpenMPI), and a rerun redoes the points that did not finish.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <optional>
#include <thread>

#include "commands.hpp"
#include "signals.hpp"
#include "../assembly/workspace.hpp"
#include "../results/errors.hpp"
#include "../studies/sweep.hpp"

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

// kAsk: a worker's report of its last point (JSON) and request for the next; kWork: the answer (a
// point, kDone, or kDoneStopFollows: a kStop sent earlier is still to be received); kStop: rank 0
// to a worker running a point: stop it (the signal's number).
enum Tag { kAsk = 1, kWork = 2, kStop = 3 };
constexpr int kDone = -1, kDoneStopFollows = -2;

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
  return {{"point", k}, {"status", r.status_text()}, {"wall_s", std::isfinite(r.wall_s) ? nlohmann::json(r.wall_s) : nlohmann::json()},
          {"t_reached", std::isfinite(r.t_reached) ? nlohmann::json(r.t_reached) : nlohmann::json()}, {"steps", r.steps},
          {"residual_evals", r.residual_evals}, {"values", v}};
}

SweepRow json_row(const nlohmann::json& j) {
  SweepRow r;
  auto num = [](const nlohmann::json& x) { return x.is_null() ? NAN : x.get<double>(); };
  r.status = SweepRow::parse_status(j["status"].get<std::string>());
  r.wall_s = num(j["wall_s"]);
  r.t_reached = num(j["t_reached"]);
  r.steps = j["steps"].get<long>();
  r.residual_evals = j["residual_evals"].get<long>();
  for (const auto& x : j["values"]) r.values.push_back(num(x));
  return r;
}

// Rank 0: the points to run, one to each rank that asks, and the index after every report. A
// signal here or one a worker reports stops the sweep: no more points, and a kStop to each rank
// running one (whose answer then says whether that kStop is still to be received).
std::vector<SweepRow> coordinate(const Sweep& s, const SweepOptions& o, int ranks, const StopToken& stop, bool show) {
  std::vector<SweepRow> rows;
  const std::vector<int> todo = plan_sweep(s, o.retry_failed, rows);
  SweepProgress pr;
  pr.total = static_cast<int>(rows.size());
  for (const SweepRow& r : rows)
    if (!r.pending()) ++(r.completed() ? pr.done : pr.failed);
  write_index(s, rows);
  std::vector<char> busy(static_cast<size_t>(ranks), 0), stop_sent(static_cast<size_t>(ranks), 0);
  bool stopping = false;
  auto stop_all = [&](int signal) {
    stopping = true;
    stop.request(signal);  // (this rank's token: the exit code)
    const std::string sig = std::to_string(signal);
    for (int r = 1; r < ranks; ++r)
      if (busy[static_cast<size_t>(r)]) {
        send_text(sig, r, kStop);
        stop_sent[static_cast<size_t>(r)] = 1;
      }
  };
  size_t next = 0;
  int working = ranks - 1;  // ranks that have not been told to stop
  while (working > 0) {
    if (stop.requested() && !stopping) stop_all(std::max(stop.signal(), 2));
    int waiting = 0;
    MPI_Status st;
    MPI_Iprobe(MPI_ANY_SOURCE, kAsk, MPI_COMM_WORLD, &waiting, &st);
    if (!waiting) {  // (polled, not blocked in MPI: a signal here reaches the running points)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      continue;
    }
    int from = st.MPI_SOURCE;
    const nlohmann::json msg = nlohmann::json::parse(receive_text(from, kAsk));
    busy[static_cast<size_t>(from)] = 0;
    if (msg.contains("point")) {
      const int k = msg["point"].get<int>();
      SweepRow& row = rows[static_cast<size_t>(k)];
      if (SweepRow got = json_row(msg); !got.pending()) row = got;  // (pending: not run, its row as planned)
      --pr.running;
      if (!row.pending() && !row.interrupted()) {
        ++(row.completed() ? pr.done : pr.failed);
        write_index(s, rows);
      }
      if (show) print_sweep_progress(pr);
    }
    if (msg.contains("stop") && !stopping) stop_all(msg["stop"].get<int>());  // a signal to that worker
    int k = kDone;
    if (stopping) k = stop_sent[static_cast<size_t>(from)] && !msg.value("stop_received", false) ? kDoneStopFollows : kDone;
    else if (next < todo.size()) k = todo[next++];
    send_text(std::to_string(k), from, kWork);
    if (k < 0) {
      --working;
    } else {
      ++pr.running;
      busy[static_cast<size_t>(from)] = 1;
    }
  }
  write_index(s, rows);
  return rows;
}

// Any other rank: ask, run, report, until told to stop. The point runs on a thread while this one
// (MPI's) watches for rank 0's kStop; a signal here stops the point and is reported to rank 0.
void work(const Sweep& s, const StopToken& stop) {
  nlohmann::json report = nlohmann::json::object();
  bool told = false;  // a kStop received (the stop is rank 0's, not a signal here)
  auto receive_stop = [&] {
    int from = 0;
    const int signal = std::stoi(receive_text(from, kStop));
    told = true;
    stop.request(signal);
  };
  for (;;) {
    if (stop.requested() && !told) report["stop"] = std::max(stop.signal(), 2);
    report["stop_received"] = told;
    send_text(report.dump(), 0, kAsk);
    int from = 0;
    const int k = std::stoi(receive_text(from, kWork));
    if (k == kDoneStopFollows) receive_stop();
    if (k < 0) return;
    if (stop.requested()) {  // (signalled while waiting) the point stays as it is: pending
      report = {{"point", k}, {"status", "pending"}, {"wall_s", nullptr}, {"t_reached", nullptr}, {"steps", 0}, {"residual_evals", 0}, {"values", nlohmann::json::array()}};
      continue;
    }
    auto run = std::async(std::launch::async, [&] {
      return run_point(s, k, stop, 1, [k](const std::string& w) { print_warning(fmt::format("point {}: {}", k, w)); });
    });
    while (run.wait_for(std::chrono::milliseconds(10)) != std::future_status::ready) {
      int stop_waiting = 0;
      MPI_Iprobe(0, kStop, MPI_COMM_WORLD, &stop_waiting, MPI_STATUS_IGNORE);
      if (stop_waiting && !told) receive_stop();
    }
    report = row_json(k, run.get());
  }
}
}  // namespace

int run_sweep_mpi(const SweepOptions& o, bool json, bool quiet) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, ranks = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  {  // Ranks beyond this node's cores (each point runs one thread): the node's first rank says so.
    MPI_Comm node;
    int local = 1, local_rank = 0;
    if (MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node) == MPI_SUCCESS) {
      MPI_Comm_size(node, &local);
      MPI_Comm_rank(node, &local_rank);
      MPI_Comm_free(&node);
    }
    // (rank 0 coordinates and waits: it runs no point, so the workers on its node are one fewer)
    const int workers = local - (rank == 0 ? 1 : 0);
    if (local_rank == 0 && !quiet)
      if (const std::string w = oversubscription(workers, 1, std::to_string(workers) + " MPI ranks running points on this node");
          !w.empty())
        print_warning(w);
  }
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
    // Rank 0 takes the sweep's lock (another sweep on this index: refused, nothing touched).
    std::optional<SweepLock> lock;
    if (rank == 0 && error.empty()) {
      try {
        lock.emplace(s);
      } catch (const ResultsError& e) {
        error = e.what();
      }
    }
    int failed = !error.empty(), refused = 0;
    MPI_Allreduce(&failed, &refused, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    if (refused) {
      if (rank == 0) fmt::print(stderr, "rfem: error: {}\n", error.empty() ? o.path + ": another rank could not read the sweep" : error);
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
