// rfem.sweep and its building blocks (rfem.load_sweep, rfem.run_point, rfem.write_index) for
// Python: the sweep runs on C++ threads while the calling thread, holding the GIL only briefly,
// polls Ctrl-C (which stops the running points; the index stays valid) and passes progress on.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <mutex>
#include <thread>

#include "rfem/studies/sweep.hpp"

namespace py = pybind11;
using namespace rfem;

namespace {

py::dict row_dict(const SweepRow& r) {
  py::dict d;
  d["status"] = r.status;
  d["wall_s"] = r.wall_s;
  d["t_reached"] = r.t_reached;
  d["steps"] = r.steps;
  d["residual_evals"] = r.residual_evals;
  d["values"] = py::array(py::cast(r.values));
  return d;
}

SweepRow dict_row(const py::dict& d) {
  SweepRow r;
  r.status = d["status"].cast<std::string>();
  r.wall_s = d.contains("wall_s") ? d["wall_s"].cast<double>() : NAN;
  r.t_reached = d.contains("t_reached") ? d["t_reached"].cast<double>() : NAN;
  r.steps = d.contains("steps") ? d["steps"].cast<long>() : 0;
  r.residual_evals = d.contains("residual_evals") ? d["residual_evals"].cast<long>() : 0;
  if (d.contains("values")) r.values = d["values"].cast<std::vector<double>>();
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
      .def("__len__", [](const Sweep& s) { return s.points.size(); });

  m.def("load_sweep", &read_sweep, py::arg("path"), py::arg("output") = "",
        "Reads a sweep file and checks every point (CaseError as rfem sweep prints it).");
  m.def("run_point", [](const Sweep& s, int k, int threads) {
    SweepRow r;
    {
      py::gil_scoped_release release;
      r = run_point(s, k, StopToken(), threads);
    }
    return row_dict(r);
  }, py::arg("sweep"), py::arg("k"), py::arg("threads") = 1,
     "Runs point k into its file; returns its row {status, wall_s, t_reached, steps, residual_evals, values}.");
  m.def("finished_point", [](const Sweep& s, int k) -> py::object {
    const auto r = finished_point(s, k);
    return r ? py::object(row_dict(*r)) : py::none();
  }, py::arg("sweep"), py::arg("k"), "Point k's row if its file holds a finished run of it, else None.");
  m.def("write_index", [](const Sweep& s, const std::vector<py::dict>& rows) {
    std::vector<SweepRow> rs;
    for (const py::dict& d : rows) rs.push_back(dict_row(d));
    py::gil_scoped_release release;
    write_index(s, rs);
  }, py::arg("sweep"), py::arg("rows"), "Writes the index from one row per point (dicts as run_point returns).");

  m.def("_sweep", [](const Sweep& s, int jobs, bool retry_failed, py::object progress) {
    SweepRequest rq;
    rq.jobs = jobs;
    rq.retry_failed = retry_failed;
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
