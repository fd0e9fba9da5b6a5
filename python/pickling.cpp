#include "pickling.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <filesystem>
#include <mutex>
#include <utility>
#include <vector>

#include "../simulation/common.hpp"
#include "rfem/version.hpp"

namespace rfem::pyorigin {

namespace {

constexpr int kCaseVersion = 1, kModelVersion = 1, kRunVersion = 2, kSweepVersion = 1;

struct Origin {
  std::weak_ptr<const Model> model;
  const Model* address = nullptr;
  Case cs;
  int n = 0;
  bool rigid = false;
};

// Models handed to Python, by address (an expired entry is dropped when the next is added).
std::mutex registry_mutex;
std::vector<Origin>& registry() {
  static std::vector<Origin> r;
  return r;
}

// A pickle's tuple taken apart by `f`: an entry of the wrong type (a tampered or foreign pickle) is
// rfem's ValueError, not pybind11's cast message.
template <class F>
auto unpickled(const char* what, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const py::cast_error&) {
    throw py::value_error(std::string("not a pickled rfem.") + what + " of this version of rfem (" + version_string +
                          "): an entry of the wrong type");
  }
}

// A count read back from a pickle: a whole number ≥ 0.
long counted(long x, const char* what, const char* entry) {
  if (x < 0) throw py::value_error(std::string("not a pickled rfem.") + what + ": " + entry + " = " + std::to_string(x) + " is negative");
  return x;
}

void check_version(const py::tuple& t, int version, std::size_t size, const char* what) {
  if (t.size() != size || t[0].cast<int>() != version)
    throw py::value_error(std::string("not a pickled rfem.") + what + " of this version of rfem (" + version_string + ")");
}

py::array_t<double> numbers(const std::vector<double>& v) { return py::array_t<double>(static_cast<py::ssize_t>(v.size()), v.data()); }
std::vector<double> numbers_from(py::handle a) {
  const auto x = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
  if (!x) throw py::value_error("not a pickled rfem object: an array expected");
  return std::vector<double>(x.data(), x.data() + x.size());
}

py::tuple info_state(const SeriesInfo& i) { return py::make_tuple(i.name, i.columns, i.units, i.description); }
SeriesInfo info_from(py::handle h) {
  const auto t = h.cast<py::tuple>();
  SeriesInfo i;
  i.name = t[0].cast<std::string>();
  i.columns = t[1].cast<std::vector<std::string>>();
  i.units = t[2].cast<std::vector<std::string>>();
  i.description = t[3].cast<std::string>();
  return i;
}
py::list infos_state(const std::vector<SeriesInfo>& v) {
  py::list out;
  for (const auto& i : v) out.append(info_state(i));
  return out;
}
std::vector<SeriesInfo> infos_from(py::handle h) {
  std::vector<SeriesInfo> out;
  for (py::handle x : h.cast<py::list>()) out.push_back(info_from(x));
  return out;
}
py::list arrays_state(const std::vector<std::vector<double>>& v) {
  py::list out;
  for (const auto& x : v) out.append(numbers(x));
  return out;
}
std::vector<std::vector<double>> arrays_from(py::handle h) {
  std::vector<std::vector<double>> out;
  for (py::handle x : h.cast<py::list>()) out.push_back(numbers_from(x));
  return out;
}

py::object series_state(const RunSeries* s) {
  if (!s) return py::none();
  const RunLayout& l = s->layout;
  py::list constants, aliases;
  for (const auto& [info, values] : l.constants) constants.append(py::make_tuple(info_state(info), numbers(values)));
  for (const auto& [a, b] : l.aliases) aliases.append(py::make_tuple(a, b));
  const py::tuple layout = py::make_tuple(infos_state(l.series), infos_state(l.flexible), l.flexible_every, constants, aliases);
  return py::make_tuple(layout, arrays_state(s->data), arrays_state(s->flexible), s->rows, s->flexible_rows);
}
std::shared_ptr<RunSeries> series_from(py::handle h) {
  if (h.is_none()) return nullptr;
  const auto t = h.cast<py::tuple>();
  auto s = std::make_shared<RunSeries>();
  const auto l = t[0].cast<py::tuple>();
  s->layout.series = infos_from(l[0]);
  s->layout.flexible = infos_from(l[1]);
  s->layout.flexible_every = l[2].cast<int>();
  for (py::handle c : l[3].cast<py::list>()) {
    const auto ct = c.cast<py::tuple>();
    s->layout.constants.emplace_back(info_from(ct[0]), numbers_from(ct[1]));
  }
  for (py::handle a : l[4].cast<py::list>()) {
    const auto at = a.cast<py::tuple>();
    s->layout.aliases.emplace_back(at[0].cast<std::string>(), at[1].cast<std::string>());
  }
  s->data = arrays_from(t[1]);
  s->flexible = arrays_from(t[2]);
  s->rows = t[3].cast<long>();
  s->flexible_rows = t[4].cast<long>();
  return s;
}

const Origin* find(const Model* m) {
  for (const Origin& o : registry())
    if (o.address == m && !o.model.expired()) return &o;
  return nullptr;
}

}  // namespace

std::shared_ptr<Model> model_from_unchecked(const py::tuple& t);
std::shared_ptr<RunResult> run_from_unchecked(const py::tuple& t);

void remember(const std::shared_ptr<const Model>& model, const Case& cs, int n, bool rigid) {
  if (!model) return;
  std::lock_guard<std::mutex> lock(registry_mutex);
  auto& r = registry();
  r.erase(std::remove_if(r.begin(), r.end(), [&](const Origin& o) { return o.model.expired() || o.address == model.get(); }),
          r.end());
  r.push_back(Origin{model, model.get(), cs, n, rigid});
}

void remember_runs(const std::vector<RunResult>& runs, const Case& cs, int n) {
  for (const RunResult& r : runs) {
    const std::string& name = r.name;
    const bool rigid = name == "rigid" || (name.size() > 6 && name.compare(name.size() - 6, 6, "/rigid") == 0);
    remember(r.model, cs, n, rigid);
  }
}

py::tuple case_state(const Case& cs) {
  // The base directory absolute: a pool's worker may start elsewhere.
  std::error_code ec;
  std::string base = std::filesystem::absolute(cs.base_dir.empty() ? std::string(".") : cs.base_dir, ec).lexically_normal().string();
  if (ec) base = cs.base_dir;
  return py::make_tuple(kCaseVersion, cs.path, cs.text, cs.overrides, base);
}

Case case_from(const py::tuple& t) {
  return unpickled("Case", [&] {
    check_version(t, kCaseVersion, 5, "Case");
    return parse_case(t[2].cast<std::string>(), t[1].cast<std::string>(), t[3].cast<std::vector<std::string>>(), t[4].cast<std::string>());
  });
}

py::tuple model_state(const Model& model) {
  std::lock_guard<std::mutex> lock(registry_mutex);
  const Origin* o = find(&model);
  if (!o)
    throw py::type_error("cannot pickle this rfem.Model: the case that built it is not known here (pickle the Case and n, and "
                         "rebuild it with rfem.model(case, n))");
  return py::make_tuple(kModelVersion, case_state(o->cs), o->n, o->rigid);
}

std::shared_ptr<Model> model_from(const py::tuple& t) {
  return unpickled("Model", [&] { return model_from_unchecked(t); });
}

std::shared_ptr<Model> model_from_unchecked(const py::tuple& t) {
  check_version(t, kModelVersion, 4, "Model");
  const Case cs = case_from(t[1].cast<py::tuple>());
  const int n = t[2].cast<int>();
  const bool rigid = t[3].cast<bool>();
  std::shared_ptr<const Model> m = model_of(cs, n);
  if (rigid) m = std::make_shared<const Model>(rigidify(*m));
  remember(m, cs, n, rigid);
  return std::const_pointer_cast<Model>(m);
}

// Per link (name, u1, u2, theta): a run's peaks and its reduction error alike.
static py::list peaks_state(const std::vector<LinkPeaks>& peaks) {
  py::list out;
  for (const LinkPeaks& p : peaks) out.append(py::make_tuple(p.name, p.u1, p.u2, p.theta));
  return out;
}
static std::vector<LinkPeaks> peaks_from(py::handle list) {
  std::vector<LinkPeaks> out;
  for (py::handle p : list.cast<py::list>()) {
    const auto pt = p.cast<py::tuple>();
    out.push_back(LinkPeaks{pt[0].cast<std::string>(), pt[1].cast<double>(), pt[2].cast<double>(), pt[3].cast<double>()});
  }
  return out;
}

py::tuple run_state(const RunResult& r) {
  const IntegratorStats& s = r.stats;
  py::object model = py::none();
  {
    std::lock_guard<std::mutex> lock(registry_mutex);
    if (r.model && find(r.model.get())) model = py::cast(std::const_pointer_cast<Model>(r.model));
  }
  return py::make_tuple(
      kRunVersion, r.name, r.status.to_string(), r.wall_s, r.t_reached,
      py::make_tuple(s.steps, s.residual_evals, s.factorizations, s.newton_iters, s.newton_fails, s.error_test_fails, s.last_step),
      r.samples, peaks_state(r.peaks), r.energy_drift, r.energy_scale, r.warnings, model, series_state(r.series.get()),
      py::make_tuple(r.sensors.rows, r.sensors.cols, numbers(r.sensors.data)), r.sensor_columns, r.sensor_units, peaks_state(r.reduction_error), r.reduction_n);
}

std::shared_ptr<RunResult> run_from(const py::tuple& t) {
  auto r = unpickled("Run", [&] { return run_from_unchecked(t); });
  // Its parts agree: counts ≥ 0, every table as long as its rows say.
  const char* what = "Run";
  counted(r->samples, what, "outputs");
  for (long c : {r->stats.steps, r->stats.residual_evals, r->stats.factorizations, r->stats.newton_iters, r->stats.newton_fails,
                 r->stats.error_test_fails})
    counted(c, what, "a statistic");
  if (counted(r->sensors.rows, what, "sensor rows") * counted(r->sensors.cols, what, "sensor columns") !=
          static_cast<long>(r->sensors.data.size()) ||
      (r->sensors.rows > 0 && r->sensor_columns.size() != static_cast<size_t>(r->sensors.cols)))
    throw py::value_error("not a pickled rfem.Run: its sensor table does not have the size it says");
  if (const RunSeries* ser = r->series.get()) {
    counted(ser->rows, what, "rows");
    counted(ser->flexible_rows, what, "flexible rows");
    bool fits = ser->data.size() == ser->layout.series.size() && ser->flexible.size() == ser->layout.flexible.size();
    for (size_t i = 0; fits && i < ser->data.size(); ++i)
      fits = static_cast<long>(ser->data[i].size()) == ser->rows * ser->layout.series[i].width();
    for (size_t i = 0; fits && i < ser->flexible.size(); ++i)
      fits = static_cast<long>(ser->flexible[i].size()) == ser->flexible_rows * ser->layout.flexible[i].width();
    if (!fits) throw py::value_error("not a pickled rfem.Run: its series do not have the rows it says");
  }
  return r;
}

std::shared_ptr<RunResult> run_from_unchecked(const py::tuple& t) {
  check_version(t, kRunVersion, 18, "Run");
  auto r = std::make_shared<RunResult>();
  r->name = t[1].cast<std::string>();
  r->status = RunStatus::parse(t[2].cast<std::string>());
  r->wall_s = t[3].cast<double>();
  r->t_reached = t[4].cast<double>();
  const auto s = t[5].cast<py::tuple>();
  r->stats = IntegratorStats{s[0].cast<long>(), s[1].cast<long>(), s[2].cast<long>(), s[3].cast<long>(), s[4].cast<long>(),
                             s[5].cast<long>(), s[6].cast<double>()};
  r->samples = t[6].cast<long>();
  r->peaks = peaks_from(t[7]);
  r->energy_drift = t[8].cast<double>();
  r->energy_scale = t[9].cast<double>();
  r->warnings = t[10].cast<std::vector<std::string>>();
  if (!t[11].is_none()) r->model = t[11].cast<std::shared_ptr<Model>>();
  r->series = series_from(t[12]);
  const auto sensors = t[13].cast<py::tuple>();
  r->sensors.rows = sensors[0].cast<long>();
  r->sensors.cols = sensors[1].cast<long>();
  r->sensors.data = numbers_from(sensors[2]);
  r->sensor_columns = t[14].cast<std::vector<std::string>>();
  r->sensor_units = t[15].cast<std::vector<std::string>>();
  r->reduction_error = peaks_from(t[16]);
  r->reduction_n = t[17].cast<int>();
  return r;
}

py::tuple sweep_state(const Sweep& s) {
  std::error_code ec;
  const auto abs = [&](const std::string& p) {
    const std::string a = std::filesystem::absolute(p, ec).lexically_normal().string();
    return ec ? p : a;
  };
  return py::make_tuple(kSweepVersion, abs(s.path), abs(s.index), s.text);
}

Sweep sweep_from(const py::tuple& t) {
  return unpickled("Sweep", [&] {
    check_version(t, kSweepVersion, 4, "Sweep");
    Sweep s = read_sweep(t[1].cast<std::string>(), t[2].cast<std::string>());
    if (s.text != t[3].cast<std::string>())
      throw py::value_error(s.path + ": the sweep file changed since this Sweep was pickled; load it again");
    return s;
  });
}

}  // namespace rfem::pyorigin
