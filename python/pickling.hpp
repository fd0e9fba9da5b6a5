#pragma once
// Pickling for process pools (multiprocessing, concurrent.futures, dask): a Case travels as its
// text, path, overrides and (absolute) base directory and is read and checked again; a Model as the
// case and n that built it (remembered when the model is handed to Python); a Run as its numbers and
// numpy arrays, with its model when that is known; a Sweep as its file and index, refused if the
// file changed since. Each state is a tuple whose first item is its format's version.
#include <pybind11/pybind11.h>

#include <memory>

#include "../cases/case_file.hpp"
#include "../core/model.hpp"
#include "../studies/runs.hpp"
#include "../studies/sweep.hpp"

namespace rfem::pyorigin {

namespace py = pybind11;

/// Notes that `model` was built from `cs` with n rfes in all (0: the case's own), rigidified for a
/// rigid run, so that it can be pickled as (case, n) and rebuilt.
void remember(const std::shared_ptr<const Model>& model, const Case& cs, int n, bool rigid = false);
/// The same for every run's model (the runs named "rigid" ran the rigidified model).
void remember_runs(const std::vector<RunResult>& runs, const Case& cs, int n);

py::tuple case_state(const Case& cs);
Case case_from(const py::tuple& t);
/// TypeError for a model whose case is not known in this process.
py::tuple model_state(const Model& model);
std::shared_ptr<Model> model_from(const py::tuple& t);
py::tuple run_state(const RunResult& r);
std::shared_ptr<RunResult> run_from(const py::tuple& t);
py::tuple sweep_state(const Sweep& s);
Sweep sweep_from(const py::tuple& t);

}  // namespace rfem::pyorigin
