#include "sweep.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <numeric>
#include <thread>

#include "../assembly/workspace.hpp"

#include "../core/check.hpp"
#include "../results/errors.hpp"
#include "../results/reader.hpp"
#include "../results/writer.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "quantities.hpp"
#include "resume.hpp"
#include "run_file.hpp"
#include "runs.hpp"

namespace rfem {

namespace {

namespace fs = std::filesystem;

}  // namespace

Sweep read_sweep(const std::string& path, const std::string& index) {
  Sweep s = read_sweep_file(path, index, kCheckpointInterval);
  const Case base = read_case(s.case_path);
  for (size_t k = 0; k < s.points.size(); ++k) {
    // Everything a run would refuse, now: the case, its simulation, n, the quantities.
    const std::string where = path + ": " + sweep_point_name(s, static_cast<int>(k)) + ": ";
    try {
      const Case c = with_overrides(base, sweep_case_overrides(s, static_cast<int>(k)));
      check_runnable(c);
      const int n = sweep_point_n(s, static_cast<int>(k));
      int rfes = 0;
      for (const auto& lp : link_parts(c, n)) rfes = std::accumulate(lp.begin(), lp.end(), rfes);
      s.points[k].cost = std::max(1, rfes) * c.sim.options.t_end;
      for (const std::string& q : s.quantities) {
        try {
          parse_quantity(c, q);
        } catch (const CaseError& e) {  // (its message names refine's option)
          std::string m = e.what();
          if (m.rfind("--quantity ", 0) == 0) m = "sweep.quantities: " + m.substr(11);
          throw CaseError(m);
        }
      }
    } catch (const CaseError& e) {
      throw CaseError(where + e.what());
    }
  }
  return s;
}

SweepRow run_point(const Sweep& s, int k, const StopToken& stop, int threads, const Warnings& warn) {
  RFEM_CHECK_INDEX(k, s.points.size(), "sweep point");
  const SweepPoint& p = s.points[static_cast<size_t>(k)];
  SweepRow row;
  row.values.assign(s.quantities.size(), NAN);
  try {
    const Case c = with_overrides(read_case(s.case_path), sweep_case_overrides(s, static_cast<int>(k)));
    const int n = sweep_point_n(s, static_cast<int>(k));
    std::vector<Quantity> qs;
    for (const std::string& q : s.quantities) qs.push_back(parse_quantity(c, q));
    fs::create_directories(s.directory);
    QuantityRecorder values(qs);
    RunRequest rq;
    rq.n = n;
    rq.threads = threads;
    rq.keep_series = false;
    rq.stop = stop;
    rq.warn = warn;
    rq.checkpoint_interval = s.checkpoint;
    // A point whose run was interrupted or killed after a checkpoint goes on from it (same case);
    // otherwise it runs from the start.
    std::optional<ResumePlan> plan;
    try {
      if (fs::exists(p.file)) plan = plan_resume(p.file);
    } catch (const std::exception&) {
    }
    if (plan && (plan->resume.empty() || plan->n != n || plan->cs.effective_text != c.effective_text)) plan.reset();
    std::vector<RunResult> runs;
    row.wall_s = 0.0;
    if (plan) {
      rq.observers = {&values};
      runs = resume_case(*plan, rq);
      const ResultsReader in(p.file);  // the runs kept: their cost
      for (const std::string& r : plan->done) {
        row.wall_s += in.number(r, "wall_time_s", 0.0);
        row.steps += static_cast<long>(in.number(r, "steps", 0.0));
        row.residual_evals += static_cast<long>(in.number(r, "residual_evals", 0.0));
      }
    } else {
      rq.observers = {&values};  // (after the file's recorder: studies/run_file.hpp)
      runs = run_into_file(c, rq, p.file, "rfem sweep " + s.path + " (" + sweep_point_name(s, k) + ")").runs;
    }
    row.status = RunStatus::completed();
    for (const RunResult& r : runs) {
      row.wall_s += r.wall_s;
      row.steps += r.stats.steps;
      row.residual_evals += r.stats.residual_evals;
      row.t_reached = r.t_reached;
      if (!r.completed()) {  // (which of the case's runs, when it has more than one)
        row.status = r.status.kind == RunStatus::Kind::Failed && runs.size() > 1 ? RunStatus::failed(r.name + ": " + r.status.reason) : r.status;
        break;
      }
    }
    if (stop.requested()) {  // not finished: goes on next time (no sweep_status in its file)
      row.status = RunStatus::interrupted(stop.signal());
      return row;
    }
    if (row.completed()) {
      row.values = values.values();
      for (size_t q = 0; q < qs.size(); ++q)
        if (!qs[q].dynamic()) row.values[q] = evaluate_quantity(c, n, qs[q]);
    }
    ResultsWriter file(p.file, Reopen{});
    if (!s.quantities.empty()) file.write_table("sweep_values", {1, static_cast<long>(row.values.size()), row.values}, s.quantities,
                                                std::vector<std::string>(s.quantities.size(), ""), "the sweep's quantities of this run");
    file.write_table("sweep_statistics", {1, 4, {row.wall_s, row.t_reached, static_cast<double>(row.steps), static_cast<double>(row.residual_evals)}},
                     {"wall_s", "t_reached", "steps", "residual_evals"}, {"s", "s", "1", "1"}, "the run's cost");
    file.write_attribute("/", "sweep_overrides", joined(p.overrides, "\n"));
    file.write_attribute("/", "sweep_status", row.status_text());  // last: a file without it did not finish
    file.close();
  } catch (const std::exception& e) {
    row.status = stop.requested() ? RunStatus::interrupted(stop.signal()) : RunStatus::failed(e.what());
  }
  return row;
}

std::vector<int> plan_sweep(const Sweep& s, bool retry_failed, std::vector<SweepRow>& rows) {
  rows.assign(s.points.size(), SweepRow{});
  std::vector<int> todo;
  for (int k = 0; k < static_cast<int>(s.points.size()); ++k) {
    SweepRow& row = rows[static_cast<size_t>(k)];
    row.values.assign(s.quantities.size(), NAN);
    const std::optional<SweepRow> f = finished_point(s, k);
    if (f && (f->completed() || !retry_failed)) row = *f;
    else todo.push_back(k);
  }
  std::stable_sort(todo.begin(), todo.end(), [&](int a, int b) { return s.points[static_cast<size_t>(a)].cost > s.points[static_cast<size_t>(b)].cost; });
  return todo;
}

std::vector<SweepRow> run_sweep(const Sweep& s, const SweepRequest& rq) {
  const SweepLock lock(s);
  return run_sweep(s, rq, lock);
}

std::vector<SweepRow> run_sweep(const Sweep& s, const SweepRequest& rq, const SweepLock&) {
  std::vector<SweepRow> rows;
  const std::vector<int> todo = plan_sweep(s, rq.retry_failed, rows);
  SweepProgress pr;
  pr.total = static_cast<int>(rows.size());
  pr.skipped = pr.total - static_cast<int>(todo.size());
  double cost_left = 0.0;
  for (int k : todo) cost_left += s.points[static_cast<size_t>(k)].cost;
  for (const SweepRow& r : rows)
    if (!r.pending()) ++(r.completed() ? pr.done : pr.failed);
  write_index(s, rows);
  const int jobs = std::max(1, std::min(rq.jobs > 0 ? rq.jobs : available_cores(), static_cast<int>(todo.size())));
  if (rq.warn)
    if (const std::string w = oversubscription(jobs, 1, "sweep: --jobs " + std::to_string(jobs)); !w.empty()) rq.warn(w);
  std::mutex lock;
  std::atomic<size_t> next{0};
  std::exception_ptr error;
  const auto t0 = std::chrono::steady_clock::now();
  double cost_done = 0.0;
  if (rq.progress) rq.progress(pr);
  auto worker = [&]() {
    for (;;) {
      if (rq.stop.requested()) return;
      {
        const std::lock_guard<std::mutex> g(lock);
        if (error) return;
      }
      const size_t i = next++;
      if (i >= todo.size()) return;
      const int k = todo[i];
      {
        const std::lock_guard<std::mutex> g(lock);
        ++pr.running;
      }
      Warnings warn;
      if (rq.warn) warn = [&](const std::string& w) { const std::lock_guard<std::mutex> g(lock); rq.warn(fmt::format("point {}: {}", k, w)); };
      SweepRow row = run_point(s, k, rq.stop, 1, warn);
      const std::lock_guard<std::mutex> g(lock);
      --pr.running;
      rows[static_cast<size_t>(k)] = row;
      if (row.interrupted()) continue;
      ++(row.completed() ? pr.done : pr.failed);
      cost_done += s.points[static_cast<size_t>(k)].cost;
      pr.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      pr.left_s = pr.elapsed_s * (cost_left - cost_done) / cost_done;
      try {
        write_index(s, rows);
        if (rq.progress) rq.progress(pr);
      } catch (...) {
        if (!error) error = std::current_exception();
      }
    }
  };
  std::vector<std::thread> team;
  for (int j = 1; j < jobs; ++j) team.emplace_back(worker);
  worker();
  for (std::thread& t : team) t.join();
  if (error) std::rethrow_exception(error);
  write_index(s, rows);
  return rows;
}

}  // namespace rfem
