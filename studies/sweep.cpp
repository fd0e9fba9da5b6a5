#include "rfem/studies/sweep.hpp"

#include <fcntl.h>
#include <fmt/core.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <numeric>
#include <thread>

#include "rfem/assembly/workspace.hpp"

#include "rfem/cases/case_reading_impl.hpp"
#include "rfem/core/check.hpp"
#include "rfem/results/errors.hpp"
#include "rfem/results/reader.hpp"
#include "rfem/results/writer.hpp"
#include "rfem/studies/inputs.hpp"
#include "rfem/studies/quantities.hpp"
#include "rfem/studies/recorders.hpp"
#include "rfem/studies/resume.hpp"
#include "rfem/studies/run_file.hpp"
#include "rfem/studies/runs.hpp"

namespace rfem {

namespace {

namespace fs = std::filesystem;
using reading::Reader;

// A parameter's values as TOML text (an integral number as an integer: `n`, counts) and numbers.
struct Values {
  std::vector<std::string> text;
  std::vector<double> number;
};

std::string number_text(double v) {
  if (std::abs(v) < 1e15 && v == std::round(v)) return fmt::format("{}", static_cast<long long>(v));
  return fmt::format("{:.17g}", v);
}

Values read_values(const Reader& r, const toml::node& n, const std::string& key) {
  Values out;
  const std::string p = "parameters." + key;
  if (const toml::table* t = n.as_table()) {  // { from, to, count }: evenly spaced, both ends included
    r.check_keys(*t, p, {"from", "to", "count"});
    const double a = r.number(*t, p, "from"), b = r.number(*t, p, "to");
    const long count = r.integer(*t, p, "count", 2, 2, 1000000);
    for (long i = 0; i < count; ++i) {
      const double v = i + 1 == count ? b : a + (b - a) * static_cast<double>(i) / static_cast<double>(count - 1);
      out.text.push_back(number_text(v));
      out.number.push_back(v);
    }
    return out;
  }
  const toml::array* a = n.as_array();
  if (!a || a->empty()) r.fail(&n, p, "must be a non-empty array of values or a range {from, to, count}");
  for (const toml::node& v : *a) {
    if (v.is_table() || v.is_array()) r.fail(&v, p, "each value must be a number, string or boolean");
    if (auto d = v.value<double>(); d && (v.is_floating_point() || v.is_integer())) {
      if (!std::isfinite(*d)) r.fail(&v, p, "values must be finite");
      out.text.push_back(v.is_integer() ? fmt::format("{}", v.as_integer()->get()) : fmt::format("{:.17g}", *d));
      out.number.push_back(*d);
    } else if (v.is_boolean()) {
      out.text.push_back(v.as_boolean()->get() ? "true" : "false");
      out.number.push_back(v.as_boolean()->get() ? 1.0 : 0.0);
    } else {
      std::ostringstream os;
      os << *v.as_string();  // quoted and escaped, as TOML
      out.text.push_back(os.str());
      out.number.push_back(NAN);
    }
  }
  return out;
}

std::string joined(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

// The point's n (rfes in all, 0: the case's own) and its case overrides.
int point_n(const Sweep& s, const SweepPoint& p) {
  for (size_t i = 0; i < s.parameters.size(); ++i)
    if (s.parameters[i] == "n") return static_cast<int>(p.values[i]);
  return 0;
}

std::vector<std::string> case_overrides(const Sweep& s, const SweepPoint& p) {
  std::vector<std::string> o = s.set;
  for (const std::string& x : p.overrides)
    if (x.rfind("n=", 0) != 0) o.push_back(x);
  return o;
}

std::string point_name(const Sweep& s, int k) {
  return fmt::format("point {} ({})", k, joined(s.points[static_cast<size_t>(k)].overrides, ", "));
}

}  // namespace

Sweep read_sweep(const std::string& path, const std::string& index) {
  Sweep s;
  s.path = path;
  {
    std::ifstream in(path);
    if (fs::is_directory(path) || !in) throw CaseError(path + ": cannot open sweep file");
    std::stringstream b;
    b << in.rdbuf();
    s.text = b.str();
  }
  toml::table root = reading::parse_toml(s.text, path);
  const Reader r(path);
  r.check_keys(root, "", {"sweep", "parameters"});
  const toml::table& st = r.table(root, "", "sweep");
  r.check_keys(st, "sweep", {"case", "set", "quantities", "combine", "output", "checkpoint"});
  const std::string dir = fs::path(path).parent_path().string();
  const std::string given = r.string(st, "sweep", "case");
  s.case_path = given.empty() || given[0] == '/' || dir.empty() ? given : dir + "/" + given;
  auto strings = [&](const char* key) {
    std::vector<std::string> out;
    if (const toml::node* n = st.get(key)) {
      const toml::array* a = n->as_array();
      if (!a) r.fail(n, std::string("sweep.") + key, "must be an array of strings");
      for (const toml::node& v : *a) {
        if (!v.is_string()) r.fail(&v, std::string("sweep.") + key, "must be an array of strings");
        out.push_back(v.as_string()->get());
      }
    }
    return out;
  };
  s.set = strings("set");
  s.quantities = strings("quantities");
  // The index is the quantities' table: a sweep without one has nothing to record.
  if (s.quantities.empty())
    r.fail(st.get("quantities") ? st.get("quantities") : &st, "sweep.quantities",
           std::string(st.get("quantities") ? "is empty" : "missing") + ": name at least one quantity to record, e.g. quantities = [\"peak:u1\"]");
  const std::string combine = r.string(st, "sweep", "combine", std::string("grid"));
  if (combine != "grid" && combine != "zip") r.fail(st.get("combine"), "sweep.combine", "must be \"grid\" or \"zip\" (got \"" + combine + "\")");
  s.zip = combine == "zip";
  s.checkpoint = r.number(st, "sweep", "checkpoint", kCheckpointInterval);
  if (!(s.checkpoint >= 0.0))
    r.fail(st.get("checkpoint"), "sweep.checkpoint", "must be 0 (none) or a positive number of seconds (got " + std::to_string(s.checkpoint) + ")");
  s.index = !index.empty() ? index : r.string(st, "sweep", "output", fs::path(path).stem().string() + ".h5");
  if (fs::path(s.index).extension() != ".h5") r.fail(st.get("output") ? st.get("output") : &st, "sweep.output", "the index must be an .h5 file (got '" + s.index + "')");
  s.directory = (fs::path(s.index).parent_path() / (fs::path(s.index).stem().string() + ".runs")).string();

  const toml::table& pt = r.table(root, "", "parameters");
  if (pt.empty()) r.fail(&pt, "parameters", "give at least one parameter, e.g. n = [24, 48, 96]");
  std::vector<Values> values;
  for (const auto& [k, v] : pt) {
    const std::string key(k.str());
    s.parameters.push_back(key);
    values.push_back(read_values(r, v, key));
    if (key == "n")
      for (double x : values.back().number)
        if (!(x >= 1 && x == std::round(x) && x <= reading::kMaxRfes)) r.fail(&v, "parameters.n", "must be whole numbers of rfes, 1 to " + std::to_string(reading::kMaxRfes));
  }
  // The points: every combination (the last parameter fastest), or the i-th value of each.
  size_t count = 1;
  if (s.zip) {
    count = values[0].text.size();
    for (size_t i = 1; i < values.size(); ++i)
      if (values[i].text.size() != count)
        r.fail(pt.get(s.parameters[i]), "parameters." + s.parameters[i],
               fmt::format("has {} values and '{}' {}: zipped parameters need as many each", values[i].text.size(), s.parameters[0], count));
  } else {
    for (const Values& v : values) count *= v.text.size();
  }
  if (count > 1000000) r.fail(&pt, "parameters", fmt::format("{} points are more than a sweep takes (1e6)", count));
  const int width = std::max(4, static_cast<int>(std::to_string(count - 1).size()));
  const Case base = read_case(s.case_path);
  for (size_t k = 0; k < count; ++k) {
    SweepPoint p;
    size_t rest = k;
    for (size_t i = values.size(); i-- > 0;) {
      const size_t j = s.zip ? k : rest % values[i].text.size();
      if (!s.zip) rest /= values[i].text.size();
      p.overrides.insert(p.overrides.begin(), s.parameters[i] + "=" + values[i].text[j]);
      p.values.insert(p.values.begin(), values[i].number[j]);
    }
    p.file = (fs::path(s.directory) / fmt::format("run{:0{}}.h5", k, width)).string();
    s.points.push_back(p);
    // Everything a run would refuse, now: the case, its simulation, n, the quantities.
    const std::string where = path + ": " + point_name(s, static_cast<int>(k)) + ": ";
    try {
      const Case c = with_overrides(base, case_overrides(s, p));
      if (!c.has_simulation) throw CaseError(c.path + ": simulation: missing table (t_end, output_dt, …) for a run");
      if (c.joints.empty()) throw CaseError(c.path + ": joints: a run needs at least one base joint");
      const int n = point_n(s, p);
      int rfes = 0;
      for (const auto& lp : link_parts(c, n)) rfes = std::accumulate(lp.begin(), lp.end(), rfes);
      s.points.back().cost = std::max(1, rfes) * c.sim.options.t_end;
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
    const Case c = with_overrides(read_case(s.case_path), case_overrides(s, p));
    const int n = point_n(s, p);
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
      runs = run_into_file(c, rq, p.file, "rfem sweep " + s.path + " (" + point_name(s, k) + ")").runs;
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
