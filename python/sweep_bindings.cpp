// rfem.sweep and its building blocks (rfem.load_sweep, rfem.run_point, rfem.write_index) for
// Python: the sweep runs on C++ threads while the calling thread, holding the GIL only briefly,
// polls Ctrl-C (which stops the running points; the index stays valid) and passes progress on.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <climits>
#include <csignal>
#include <mutex>
#include <thread>

#include "arguments.hpp"
#include "pickling.hpp"
#include "../solvers/run_status.hpp"
#include "../studies/sweep.hpp"

namespace py = pybind11;
using namespace rfem;
namespace args = rfem::pyargs;

namespace {

const Sweep& sweep_of(py::handle v) { return args::object<Sweep>(v, "sweep", "an rfem.Sweep (rfem.load_sweep)"); }

// Point k of the sweep: 0 to its size - 1.
int point(const Sweep& s, py::handle k) {
  if (s.points.empty()) throw py::value_error("k: the sweep has no points");
  return static_cast<int>(args::integer(k, "k", 0, static_cast<long>(s.points.size()) - 1,
                                        "a point of the sweep, 0 to " + std::to_string(s.points.size() - 1)));
}

py::dict row_dict(const SweepRow& r) {
  py::dict d;
  d["status"] = r.status_text();  // "pending" or the RunStatus's text
  d["wall_s"] = r.wall_s;
  d["t_reached"] = r.t_reached;
  d["steps"] = r.steps;
  d["residual_evals"] = r.residual_evals;
  d["values"] = py::array(py::cast(r.values));
  return d;
}

// A row as run_point returns it, its entries checked (TypeError/ValueError naming rows[k]["key"]).
SweepRow dict_row(py::handle row, const std::string& name) {
  if (!py::isinstance<py::dict>(row)) args::type_error(name, "a dict (a row as run_point returns it)", row);
  const py::dict d = py::reinterpret_borrow<py::dict>(row);
  if (!d.contains("status")) throw py::value_error(name + ": has no \"status\"");
  auto key = [&](const char* k) { return name + "[\"" + k + "\"]"; };
  auto number = [&](const char* k) {  // NaN: not known
    if (!d.contains(k)) return static_cast<double>(NAN);
    const py::handle v = d[k];
    if (PyBool_Check(v.ptr()) || !(PyFloat_Check(v.ptr()) || PyIndex_Check(v.ptr()))) args::type_error(key(k), "a number", v);
    return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
  };
  SweepRow r;
  r.status = SweepRow::parse_status(args::text(d["status"], key("status")));
  r.wall_s = number("wall_s");
  r.t_reached = number("t_reached");
  r.steps = d.contains("steps") ? args::integer(d["steps"], key("steps"), 0, LONG_MAX, "a count, 0 or more") : 0;
  r.residual_evals = d.contains("residual_evals") ? args::integer(d["residual_evals"], key("residual_evals"), 0, LONG_MAX, "a count, 0 or more") : 0;
  if (d.contains("values")) {
    const py::handle v = d["values"];
    if (PyUnicode_Check(v.ptr()) || !py::isinstance<py::iterable>(v)) args::type_error(key("values"), "a list of numbers", v);
    for (py::handle x : py::reinterpret_borrow<py::iterable>(v)) {
      if (PyBool_Check(x.ptr()) || !(PyFloat_Check(x.ptr()) || PyIndex_Check(x.ptr()))) args::type_error(key("values"), "a list of numbers", x);
      r.values.push_back(py::float_(py::reinterpret_borrow<py::object>(x)).cast<double>());  // NaN: not reached
    }
  }
  return r;
}

}  // namespace

void bind_sweep(py::module_& m) {
  py::class_<Sweep>(m, "Sweep", "A sweep file as read and checked (rfem.load_sweep): its points and where they go.")
      .def_readonly("path", &Sweep::path)
      .def_readonly("case_path", &Sweep::case_path)
      .def_readonly("parameters", &Sweep::parameters)
      .def_readonly("quantities", &Sweep::quantities)
      .def_readonly("index", &Sweep::index)
      .def_readonly("directory", &Sweep::directory)
      .def_property_readonly("points", [](const Sweep& s) {
        py::list out;
        for (const SweepPoint& p : s.points)
          out.append(py::dict(py::arg("overrides") = p.overrides, py::arg("values") = p.values, py::arg("file") = p.file,
                              py::arg("cost") = p.cost));
        return out;
      })
      .def("__len__", [](const Sweep& s) { return s.points.size(); })
      .def("__repr__", [](const Sweep& s) {
        return "<rfem.Sweep " + s.path + ": " + std::to_string(s.points.size()) + " points over " +
               std::to_string(s.parameters.size()) + " parameters, index " + s.index + ">";
      })
      .def(py::pickle(&pyorigin::sweep_state, &pyorigin::sweep_from));

  m.def("load_sweep", [](args::Typed<"Union[str, os.PathLike]"> path, args::Typed<"Optional[Union[str, os.PathLike]]"> output) {
    return read_sweep(args::path(path, "path"), args::path(output, "output", true));
  }, py::arg("path"), py::arg("output") = "", "Reads a sweep file and checks every point (CaseError as rfem sweep prints it).");
  m.def("run_point", [](args::Typed<"Sweep"> sweep, args::Typed<"int"> k_arg, args::Typed<"int"> threads_arg) {
    const Sweep& s = sweep_of(sweep);
    const int k = point(s, k_arg);
    const int threads = args::threads(threads_arg);
    SweepRow r;
    {
      py::gil_scoped_release release;
      r = run_point(s, k, StopToken(), threads);
    }
    return row_dict(r);
  }, py::arg("sweep"), py::arg("k"), py::arg("threads") = 1,
     "Runs point k into its file; returns its row {status, wall_s, t_reached, steps, residual_evals, values}.");
  m.def("finished_point", [](args::Typed<"Sweep"> sweep, args::Typed<"int"> k) -> py::object {
    const Sweep& s = sweep_of(sweep);
    const auto r = finished_point(s, point(s, k));
    return r ? py::object(row_dict(*r)) : py::none();
  }, py::arg("sweep"), py::arg("k"), "Point k's row if its file holds a finished run of it, else None.");
  m.def("write_index", [](args::Typed<"Sweep"> sweep, args::Typed<"List[dict]"> rows) {
    const Sweep& s = sweep_of(sweep);
    if (PyUnicode_Check(rows.ptr()) || !py::isinstance<py::iterable>(rows)) args::type_error("rows", "a list of dicts (run_point's rows)", rows);
    std::vector<SweepRow> rs;
    for (py::handle d : py::reinterpret_borrow<py::iterable>(rows)) rs.push_back(dict_row(d, "rows[" + std::to_string(rs.size()) + "]"));
    py::gil_scoped_release release;
    write_index(s, rs);
  }, py::arg("sweep"), py::arg("rows"), "Writes the index from one row per point (dicts as run_point returns).");

  m.def("_sweep", [](args::Typed<"Sweep"> sweep, args::Typed<"int"> jobs, args::Typed<"bool"> retry_failed, args::Typed<"Optional[Callable[[dict], Any]]"> progress_arg) {
    const Sweep& s = sweep_of(sweep);
    const py::object progress = args::callback(progress_arg, "progress");
    SweepRequest rq;
    rq.jobs = static_cast<int>(args::integer(jobs, "jobs", 0, INT_MAX, "0 (the cores) or a positive integer"));
    rq.retry_failed = args::flag(retry_failed, "retry_failed");
    std::mutex lock;
    SweepProgress last;
    bool fresh = false;
    rq.progress = [&](const SweepProgress& p) {
      const std::lock_guard<std::mutex> g(lock);
      last = p;
      fresh = true;
    };
    std::vector<std::string> warnings;
    rq.warn = [&](const std::string& w) {
      const std::lock_guard<std::mutex> g(lock);
      warnings.push_back(w);
    };
    std::vector<SweepRow> rows;
    std::exception_ptr failure;
    py::object error = py::none();
    {
      py::gil_scoped_release release;
      std::atomic<bool> done{false};
      std::thread t([&] {
        try {
          rows = run_sweep(s, rq);
        } catch (...) {
          failure = std::current_exception();
        }
        done = true;
      });
      while (!done) {
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
        py::gil_scoped_acquire gil;
        if (error.is_none() && PyErr_CheckSignals() != 0) {
          error = py::error_already_set().value();
          rq.stop.request(SIGINT);
        }
        SweepProgress p;
        {
          const std::lock_guard<std::mutex> g(lock);
          if (!fresh) continue;
          p = last;
          fresh = false;
        }
        if (error.is_none() && !progress.is_none()) {
          try {
            progress(py::dict(py::arg("done") = p.done, py::arg("failed") = p.failed, py::arg("running") = p.running,
                              py::arg("total") = p.total, py::arg("left_s") = p.left_s));
          } catch (py::error_already_set& e) {
            error = e.value();
            rq.stop.request(SIGINT);
          }
        }
      }
      t.join();
    }
    if (failure) std::rethrow_exception(failure);
    py::list out;
    for (const SweepRow& r : rows) out.append(row_dict(r));
    return py::make_tuple(out, error, warnings);
  }, py::arg("sweep"), py::arg("jobs"), py::arg("retry_failed"), py::arg("progress"));
}
