#pragma once
// Python's side of a C++ run (rfem.run, refine, Simulation, run_controlled): C++ integrates with the
// GIL released; its progress callback takes the GIL back to poll Python's signals (Ctrl-C) and call
// the script's progress. The first Python exception is kept (the binding raises it when the call
// returns: RunInterrupted for Ctrl-C) and stops the run within a step; nothing crosses C++ frames.
#include <pybind11/pybind11.h>

#include <csignal>

#include "../studies/runs.hpp"

namespace rfem::pyguard {

namespace py = pybind11;

struct CallGuard {
  StopToken stop;
  py::object error = py::none();     ///< the exception to raise when the call returns
  py::object bad = py::none();       ///< what a controller returned that it must not: TypeError, ValueError
  py::object progress = py::none();  ///< the script's progress(dict), or None

  /// Keeps the exception being handled (the first one only) and stops the run. GIL held.
  void keep(py::error_already_set& e) {
    if (!error.is_none()) return;
    error = e.value();
    stop.request(PyErr_GivenExceptionMatches(error.ptr(), PyExc_KeyboardInterrupt) ? SIGINT : 0);
  }
  /// False (and the run stopped) once a signal's handler raised, now or before. GIL held.
  bool signals() {
    if (!error.is_none()) return false;
    if (PyErr_CheckSignals() != 0) {
      py::error_already_set e;
      keep(e);
      return false;
    }
    return true;
  }
  /// The loop's callback (GIL released): signals, then the script's progress with `p` if any.
  void beat(const Progress* p) {
    py::gil_scoped_acquire gil;
    if (!signals() || !p || progress.is_none()) return;
    try {
      py::dict d;
      d["run"] = p->run;
      d["t"] = p->t;
      d["t_end"] = p->t_end;
      d["steps"] = p->steps;
      progress(d);
    } catch (py::error_already_set& e) {
      keep(e);
    }
  }
  /// The kept exception, handed over once (and the script's callback let go). GIL held.
  py::object take() {
    py::object e = error;
    error = py::none();
    progress = py::none();
    return e;
  }
};

}  // namespace rfem::pyguard
