// rfem's Python module (_rfem, wrapped by the package python/rfem/__init__.py): the library's
// studies as Python calls. It translates arguments and results only: cases, runs, statics, modes
// and refinement are library calls, with the library's checks and messages. Long calls release
// the GIL; a heartbeat from the integration loop takes it back to poll Python's signals (Ctrl-C
// stops the run within a step, its partial results kept) and to call the user's progress callback.
// Series come back as read-only numpy views of the library's own buffers (no copy). Arguments are
// checked in arguments.hpp (TypeError, ValueError naming the argument).
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <omp.h>

#include <csignal>
#include <memory>

#include "../cases/case_file.hpp"
#include "../results/errors.hpp"
#include "../results/xdmf.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../studies/accuracy.hpp"
#include "../studies/modes_study.hpp"
#include "../studies/refine.hpp"
#include "../studies/resume.hpp"
#include "../studies/run_file.hpp"
#include "../studies/runs.hpp"
#include "../studies/show.hpp"
#include "../studies/static_study.hpp"
#include "arguments.hpp"
#include "call_guard.hpp"
#include "pickling.hpp"
#include "rfem/version.hpp"

namespace py = pybind11;
using namespace rfem;
namespace args = rfem::pyargs;

namespace {

// A read-only numpy view of `rows` × `cols` doubles owned by `owner` (kept alive by the array).
template <class Owner>
py::array view(std::shared_ptr<Owner> owner, const double* data, long rows, long cols, bool flat = false) {
  auto* keep = new std::shared_ptr<Owner>(std::move(owner));
  py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<Owner>*>(p); });
  std::vector<py::ssize_t> shape{rows}, strides{static_cast<py::ssize_t>(sizeof(double) * (flat ? 1 : cols))};
  if (!flat) {
    shape.push_back(cols);
    strides.push_back(sizeof(double));
  }
  static const double empty = 0.0;  // numpy wants an address even for no data
  py::array a(py::dtype::of<double>(), shape, strides, data ? data : &empty, base);
  a.attr("flags").attr("writeable") = false;
  return a;
}

py::array vector_array(const Eigen::VectorXd& v) { return py::array_t<double>(v.size(), v.data()); }

using pyguard::CallGuard;  // (Ctrl-C and the script's progress while C++ runs: call_guard.hpp)

// How a file was made from Python: the script's command line and the call.
std::string python_made_by(const std::string& call) {
  std::string argv;
  try {
    py::gil_scoped_acquire gil;
    for (auto a : py::module_::import("sys").attr("argv")) argv += (argv.empty() ? "" : " ") + py::str(a).cast<std::string>();
  } catch (...) {
  }
  return argv + (argv.empty() ? "" : " ") + "(Python " + call + ")";
}

py::dict stats_dict(const IntegratorStats& s) {
  py::dict d;
  d["steps"] = s.steps;
  d["residual_evals"] = s.residual_evals;
  d["factorizations"] = s.factorizations;
  d["newton_iters"] = s.newton_iters;
  d["newton_fails"] = s.newton_fails;
  d["error_test_fails"] = s.error_test_fails;
  d["last_step"] = s.last_step;
  return d;
}

std::vector<RunName> run_names(const std::vector<std::string>& names) {
  std::vector<RunName> out;
  for (const auto& n : names) {
    RunName r;
    if (!parse(n, r)) throw py::value_error("no run named '" + n + "' (run, rigid, kinematic, force)");
    out.push_back(r);
  }
  return out;
}

// A run request from Python: progress and Ctrl-C through `pending`, warnings collected.
RunRequest python_request(const std::shared_ptr<CallGuard>& pending, py::handle progress, py::handle threads, py::handle keep_series,
                          py::handle checkpoint, std::vector<std::string>& warnings) {
  pending->progress = args::callback(progress, "progress");
  RunRequest rq;
  rq.threads = args::threads(threads);
  rq.keep_series = args::flag(keep_series, "keep_series");
  rq.checkpoint_interval = args::non_negative(checkpoint, "checkpoint", "a finite number of seconds, 0 (none) or more");
  rq.stop = pending->stop;
  rq.progress = [pending](const Progress& p) { pending->beat(&p); };
  rq.progress_interval = 0.1;
  rq.warn = [&warnings](const std::string& w) { warnings.push_back(w); };
  return rq;
}

}  // namespace

void bind_sweep(py::module_& m);  // (sweep_bindings.cpp)
void bind_simulation(py::module_& m);  // (simulation_bindings.cpp)
void bind_accuracy(py::module_& m);  // (accuracy_bindings.cpp)

PYBIND11_MODULE(_rfem, m) {
  m.doc() = "rfem's compiled core; use the package `rfem` (help(rfem)).";
  m.attr("__version__") = version_string;
  m.attr("build") = build_description();
  py::register_exception<CaseError>(m, "CaseError", PyExc_ValueError);
  py::register_exception<ResultsError>(m, "ResultsError", PyExc_OSError);
  m.attr("MAX_RFES") = kMaxRfes;  // the most rfes n may ask for (the case file's limit)
  m.def("_after_fork", [] {  // (os.register_at_fork: one thread by default in the child, never a team)
    args::forked() = true;
    omp_set_num_threads(1);
  });

  py::class_<RunStatus>(m, "RunStatus", "How a run ended, parsed from its status text (RunStatus.parse(run.status)).")
      .def_static("parse", [](args::Typed<"str"> text) { return RunStatus::parse(args::text(text, "text")); }, py::arg("text"),
                  "'running', 'completed', 'interrupted (signal N)', 'failed: why'; other text is a failure with it as reason")
      .def_property_readonly("kind", [](const RunStatus& s) {
        switch (s.kind) {
          case RunStatus::Kind::Running: return "running";
          case RunStatus::Kind::Completed: return "completed";
          case RunStatus::Kind::Interrupted: return "interrupted";
          case RunStatus::Kind::Failed: break;
        }
        return "failed";
      }, "running, completed, interrupted or failed")
      .def_property_readonly("completed", &RunStatus::is_completed)
      .def_readonly("signal", &RunStatus::signal, "int: interrupted, the signal that asked for the stop (0: a caller's stop)")
      .def_readonly("reason", &RunStatus::reason, "str: failed, why")
      .def("__str__", &RunStatus::to_string)
      .def("__repr__", [](const RunStatus& s) { return "<rfem.RunStatus " + s.to_string() + ">"; })
      .def(py::pickle([](const RunStatus& s) { return s.to_string(); }, [](const std::string& t) { return RunStatus::parse(t); }));

  py::class_<Case>(m, "Case", "A case: a TOML case file as read and checked (rfem.load, rfem.Case.from_text).")
      .def_static("load", [](args::Typed<"Union[str, os.PathLike]"> path, args::Typed<"List[str]"> overrides) {
        return read_case(args::path(path, "path"), args::texts(overrides, "overrides"));
      }, py::arg("path"), py::arg("overrides") = py::tuple(),
         "Reads and checks a case file; overrides are 'key.path=value' strings (as rfem --set).")
      .def_static("from_text", [](args::Typed<"str"> text, args::Typed<"str"> name, args::Typed<"List[str]"> overrides, args::Typed<"Optional[Union[str, os.PathLike]]"> base_dir) {
        return parse_case(args::text(text, "text"), args::text(name, "name"), args::texts(overrides, "overrides"),
                          args::path(base_dir, "base_dir", true));
      }, py::arg("text"), py::arg("name") = "<text>", py::arg("overrides") = py::tuple(), py::arg("base_dir") = "",
         "A case from TOML text; `name` stands for the file in messages, table files are found in base_dir.")
      .def("with_overrides", [](const Case& c, args::Typed<"List[str]"> overrides) { return with_overrides(c, args::texts(overrides, "overrides")); },
           py::arg("overrides"), "The case with more 'key.path=value' overrides, read and checked again (CaseError names the key).")
      .def_readonly("path", &Case::path)
      .def_readonly("text", &Case::text, "the case file as read")
      .def_readonly("effective_text", &Case::effective_text, "the case after its overrides, as TOML")
      .def_readonly("overrides", &Case::overrides)
      .def_readonly("warnings", &Case::warnings, "legal but suspicious values, one line each")
      .def_property_readonly("name", [](const Case& c) { return c.name.empty() ? c.path : c.name; })
      .def_readonly("description", &Case::description)
      .def_property_readonly("links", [](const Case& c) {
        std::vector<std::string> v;
        for (const auto& l : c.links) v.push_back(l.name);
        return v;
      }, "the flexible links' names")
      .def_property_readonly("joints", [](const Case& c) {
        std::vector<std::string> v;
        for (const auto& j : c.joints) v.push_back(j.name);
        return v;
      }, "the joints' names (a free base's six first)")
      .def_property_readonly("procedure", [](const Case& c) { return to_string(c.sim.procedure); })
      .def_readonly("has_simulation", &Case::has_simulation)
      .def_property_readonly("t_end", [](const Case& c) { return c.sim.options.t_end; })
      .def_property_readonly("output_dt", [](const Case& c) { return c.sim.options.output_dt; })
      .def("__repr__", [](const Case& c) {
        return "<rfem.Case " + (c.name.empty() ? c.path : c.name) +
               (c.overrides.empty() ? "" : " with " + std::to_string(c.overrides.size()) + " overrides") + ">";
      })
      .def(py::pickle(&pyorigin::case_state, &pyorigin::case_from));

  py::class_<Model, std::shared_ptr<Model>>(m, "Model", "A case's model: its links cut into rfes, its joints.")
      .def_property_readonly("n", &Model::n, "rfes of all links")
      .def_property_readonly("m", &Model::m, "joints")
      .def_property_readonly("dof", &Model::dof, "int: coordinates, 6 per rfe and one per joint")
      .def_readonly("free_base", &Model::free_base)
      .def_readonly("gravity", &Model::gravity)
      .def_property_readonly("links", [](const Model& md) {
        py::list out;
        for (const auto& L : md.links) out.append(py::dict(py::arg("name") = L.name, py::arg("n") = L.n(), py::arg("length") = L.d.length));
        return out;
      })
      .def_property_readonly("joints", [](const Model& md) {
        py::list out;
        for (const auto& j : md.joints)
          out.append(py::dict(py::arg("name") = j.name, py::arg("type") = j.type == JointType::Revolute ? "revolute" : "prismatic"));
        return out;
      })
      .def("__repr__", [](const Model& md) {
        return "<rfem.Model n=" + std::to_string(md.n()) + " rfes, m=" + std::to_string(md.m()) + " joints>";
      })
      .def(py::pickle(&pyorigin::model_state, &pyorigin::model_from));
  m.def("model", [](args::Typed<"Union[Case, str, os.PathLike]"> c, args::Typed<"Optional[int]"> n_arg) {
    const args::CaseArg cs(c);
    const int n = args::rfes(n_arg);
    const auto md = model_of(*cs, n);
    pyorigin::remember(md, *cs, n);
    return std::const_pointer_cast<Model>(md);
  },
        py::arg("case"), py::arg("n") = py::none(), "The case's model with n rfes in all (None: the case's own discretisation).");

  py::class_<RunResult, std::shared_ptr<RunResult>>(m, "Run", "One run of a study: status, statistics, peaks and series.")
      .def_readonly("name", &RunResult::name)
      .def_property_readonly("status", [](const RunResult& r) { return r.status.to_string(); })
      .def_property_readonly("completed", &RunResult::completed)
      .def_readonly("wall_time", &RunResult::wall_s, "[s]")
      .def_readonly("t_reached", &RunResult::t_reached, "[s]")
      .def_readonly("outputs", &RunResult::samples)
      .def_property_readonly("stats", [](const RunResult& r) { return stats_dict(r.stats); })
      .def_property_readonly("peaks", [](const RunResult& r) {
        py::dict d;
        for (const auto& p : r.peaks) d[py::str(p.name)] = py::dict(py::arg("u1") = p.u1, py::arg("u2") = p.u2, py::arg("theta") = p.theta);
        return d;
      }, "dict: per link, peak |u1|, |u2| [m], |theta| [rad]")
      .def_property_readonly("reduction_error", [](const RunResult& r) -> py::object {
        if (r.reduction_n == 0) return py::none();
        py::dict d;
        for (const auto& p : r.reduction_error)
          d[py::str(p.name)] = py::dict(py::arg("u1") = p.u1, py::arg("u2") = p.u2, py::arg("theta") = p.theta, py::arg("n") = r.reduction_n);
        return d;
      }, "a run of reduced links: per link, its peaks' estimated reduction error (reduced - full peaks, both at the "
         "coarse n given as 'n'; README, \"Reduced links\"); None without one")
      .def_readonly("energy_drift", &RunResult::energy_drift, "max |balance(t) - balance(0)| [J]")
      .def_readonly("warnings", &RunResult::warnings, "where the solution left the small deformation the model assumes")
      .def_readonly("energy_scale", &RunResult::energy_scale, "[J]")
      .def_property_readonly("model", [](const RunResult& r) { return std::const_pointer_cast<Model>(r.model); })
      .def_property_readonly("names", [](const RunResult& r) {
        return r.series ? r.series->names() : std::vector<std::string>{};
      }, "the series kept (empty if the run kept none)")
      .def("table", [](const std::shared_ptr<RunResult>& r, args::Typed<"str"> series) {
        const std::string name = args::text(series, "name");
        if (!r->series) throw py::value_error("the run kept no series (keep_series=False)");
        const RunSeries::View v = r->series->view(name);
        return view(std::shared_ptr<const RunSeries>(r->series), v.data, v.rows, v.info->width());
      }, py::arg("name"), "Series `name` (rows = outputs) as a read-only array, e.g. 'joint_tau', 'links/upper/tip_deflection'.")
      .def("column", [](const std::shared_ptr<RunResult>& r, args::Typed<"str"> series, args::Typed<"Union[str, int]"> column) {
        const std::string name = args::text(series, "name");
        if (!r->series) throw py::value_error("the run kept no series (keep_series=False)");
        const RunSeries::View v = r->series->view(name);
        long col = -1;
        if (PyUnicode_Check(column.ptr())) {  // by the column's name in the file ("u1")
          const std::string c = args::text(column, "column");
          const auto& cs = v.info->columns;
          const auto it = std::find(cs.begin(), cs.end(), c);
          if (it == cs.end()) {
            std::string known;
            for (const auto& x : cs) known += (known.empty() ? "" : ", ") + x;
            throw py::key_error("no column '" + c + "' in " + name + " (columns: " + known + ")");
          }
          col = it - cs.begin();
        } else {
          col = args::integer(column, "column", 0, INT_MAX, "a column's name or number, 0 or more");
          if (col >= v.info->width()) throw py::index_error("no column " + std::to_string(col) + " in " + name);
        }
        const long w = v.info->width();
        auto* keep = new std::shared_ptr<const RunSeries>(r->series);
        py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<const RunSeries>*>(p); });
        static const double empty = 0.0;
        py::array a(py::dtype::of<double>(), std::vector<py::ssize_t>{v.rows},
                    std::vector<py::ssize_t>{static_cast<py::ssize_t>(sizeof(double) * w)}, v.data ? v.data + col : &empty, base);
        a.attr("flags").attr("writeable") = false;
        return a;
      }, py::arg("name"), py::arg("column"),
         "One column of a series as a read-only 1-D array (a row per output): by its name in the file ('u1') or its number.")
      .def("info", [](const RunResult& r, args::Typed<"str"> series) {
        const std::string name = args::text(series, "name");
        if (!r.series) throw py::value_error("the run kept no series (keep_series=False)");
        const SeriesInfo& i = *r.series->view(name).info;
        return py::dict(py::arg("name") = i.name, py::arg("columns") = i.columns, py::arg("units") = i.units,
                        py::arg("description") = i.description);
      }, py::arg("name"), "Columns, units and description of series `name`.")
      .def_property_readonly("sensors", [](const RunResult& r) {
        py::array_t<double> a({static_cast<py::ssize_t>(r.sensors.rows), static_cast<py::ssize_t>(r.sensors.cols)});
        std::copy(r.sensors.data.begin(), r.sensors.data.end(), a.mutable_data());
        return a;
      }, "the case's [[sensors]] at every output as measured: a row per output, `time` first (sensor_columns)")
      .def_readonly("sensor_columns", &RunResult::sensor_columns, "the columns of `sensors` ('time', 'NAME', 'NAME/q', …)")
      .def_readonly("sensor_units", &RunResult::sensor_units)
      .def("__repr__", [](const RunResult& r) {
        return "<rfem.Run " + r.name + ": " + r.status.to_string() + ", " + std::to_string(r.samples) + " outputs>";
      })
      .def(py::pickle(&pyorigin::run_state, &pyorigin::run_from));

  m.def("_run", [](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"Optional[int]"> n_arg, args::Typed<"Optional[Union[str, os.PathLike]]"> output_arg, args::Typed<"Optional[List[str]]"> runs, args::Typed<"int"> threads,
                   args::Typed<"bool"> keep_series, args::Typed<"Optional[Callable[[dict], Any]]"> progress, args::Typed<"float"> checkpoint,
                   args::Typed<"Optional[float]"> reduction_allowed, args::Typed<"bool"> reduction_check) {
    const args::CaseArg cs_arg(case_arg);
    const Case& cs = *cs_arg;
    const int n = args::rfes(n_arg);
    const std::string output = args::path(output_arg, "output", true);
    auto pending = std::make_shared<CallGuard>();
    std::vector<std::string> warnings;
    RunRequest rq = python_request(pending, progress, threads, keep_series, checkpoint, warnings);
    rq.n = n;
    rq.runs = run_names(args::texts(runs, "runs"));
    if (!reduction_allowed.is_none()) rq.reduction_allowed = py::cast<double>(reduction_allowed);
    rq.reduction_error = args::flag(reduction_check, "reduction_check");
    std::vector<RunResult> results;
    {
      const std::string made_by = output.empty() ? "" : python_made_by("rfem.run");
      py::gil_scoped_release release;
      // Into a file: the one path the program takes (studies/run_file.hpp); else in memory only.
      results = output.empty() ? run_case(cs, rq) : run_into_file(cs, rq, output, made_by).runs;
    }
    pyorigin::remember_runs(results, cs, n);
    py::list out;
    for (auto& r : results) out.append(std::make_shared<RunResult>(std::move(r)));
    py::object error = pending->take();
    return py::make_tuple(out, error, warnings);
  }, py::arg("case"), py::arg("n"), py::arg("output"), py::arg("runs"), py::arg("threads"), py::arg("keep_series"),
     py::arg("progress"), py::arg("checkpoint"), py::arg("reduction_allowed") = py::none(), py::arg("reduction_check") = true);

  m.attr("CHECKPOINT_INTERVAL") = kCheckpointInterval;

  m.def("_resume", [](args::Typed<"Union[str, os.PathLike]"> path_arg, args::Typed<"int"> threads, args::Typed<"bool"> keep_series, args::Typed<"Optional[Callable[[dict], Any]]"> progress, args::Typed<"float"> checkpoint) {
    const std::string path = args::path(path_arg, "resume");
    auto pending = std::make_shared<CallGuard>();
    std::vector<std::string> warnings;
    RunRequest rq = python_request(pending, progress, threads, keep_series, checkpoint, warnings);
    std::vector<RunResult> results;
    std::vector<std::string> done;
    std::optional<ResumePlan> plan_kept;
    {
      py::gil_scoped_release release;
      const ResumePlan& plan = plan_kept.emplace(plan_resume(path));
      done = plan.done;
      results = resume_case(plan, rq);
      if (!results.empty()) write_views(plan.cs, *results.back().model, path, rq.warn);
    }
    pyorigin::remember_runs(results, plan_kept->cs, plan_kept->n);
    py::list out;
    for (auto& r : results) out.append(std::make_shared<RunResult>(std::move(r)));
    py::object error = pending->take();
    return py::make_tuple(out, error, warnings, done);
  }, py::arg("path"), py::arg("threads"), py::arg("keep_series"), py::arg("progress"), py::arg("checkpoint"));

  m.def("write_xdmf", [](args::Typed<"Union[str, os.PathLike]"> results_arg, args::Typed<"Optional[List[str]]"> runs_arg) {
    const std::string results = args::path(results_arg, "results");
    const std::vector<std::string> runs = args::texts(runs_arg, "runs");
    py::gil_scoped_release release;
    return write_xdmf(results, runs);
  }, py::arg("results"), py::arg("runs") = py::tuple(),
     "ParaView (XDMF 2) files beside a results file for every run (or `runs`) that stored its poses "
     "(simulation.store_flexible_every > 0); returns the paths written. rfem view RESULTS.h5 does the same.");

  m.def("_show", [](args::Typed<"Union[Case, str, os.PathLike]"> cs, args::Typed<"Optional[int]"> n) {
    const ModelSummary s = show_model(*args::CaseArg(cs), args::rfes(n));
    py::list entries;
    for (const TreeEntry& e : s.entries)
      entries.append(py::dict(py::arg("kind") = e.kind, py::arg("name") = e.name, py::arg("depth") = e.depth,
                              py::arg("parent") = e.parent, py::arg("where") = e.where, py::arg("mass") = e.mass,
                              py::arg("length") = e.length, py::arg("rfes") = e.rfes, py::arg("detail") = e.detail,
                              py::arg("coordinates") = e.coordinates));
    py::list frames;
    for (const TreeEntry& f : s.frames)
      frames.append(py::dict(py::arg("name") = f.name, py::arg("parent") = f.parent, py::arg("where") = f.where));
    return py::make_tuple(format_summary(s), entries, s.urdf, frames);
  }, py::arg("case"), py::arg("n"));

  py::class_<StaticStudy, std::shared_ptr<StaticStudy>>(m, "StaticResult", "A static equilibrium (rfem.static).", py::dynamic_attr())
      .def_property_readonly("n", [](const StaticStudy& s) { return s.model->n(); })
      .def_property_readonly("iterations", [](const StaticStudy& s) { return s.solution.iterations; })
      .def_property_readonly("load_steps", [](const StaticStudy& s) { return s.solution.load_steps; })
      .def_property_readonly("residual", [](const StaticStudy& s) { return s.solution.residual; }, "[N]")
      .def_property_readonly("q", [](const StaticStudy& s) { return vector_array(s.solution.q); }, "all coordinates")
      .def_property_readonly("elastic_energy", [](const StaticStudy& s) { return s.energies.elastic; }, "[J]")
      .def_property_readonly("gravity_energy", [](const StaticStudy& s) { return s.energies.gravity; }, "[J]")
      .def_readonly("warnings", &StaticStudy::warnings)
      .def_property_readonly("tips", [](const StaticStudy& s) {
        py::dict d;
        for (const LinkTip& t : s.tips)
          d[py::str(t.name)] = py::dict(py::arg("n") = t.n, py::arg("displacement") = vector_array(t.motion.head<3>()),
                                        py::arg("rotation") = vector_array(t.motion.tail<3>()));
        return d;
      }, "dict: per link, its free end's displacement [m] and rotation [rad] in its {r}")
      .def_property_readonly("model", [](const StaticStudy& s) { return std::const_pointer_cast<Model>(s.model); })
      .def("__repr__", [](const StaticStudy& s) {
        return "<rfem.StaticResult n=" + std::to_string(s.model->n()) + " rfes, " + std::to_string(s.solution.iterations) +
               " iterations, residual " + py::repr(py::float_(s.solution.residual)).cast<std::string>() + " N>";
      });
  m.def("_static", [](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"Optional[int]"> n_arg, args::Typed<"Optional[float]"> rate, args::Typed<"int"> joint) {
    const args::CaseArg cs(case_arg);
    const int n = args::rfes(n_arg);
    const JointRate r = args::joint_rate(rate, joint);
    std::shared_ptr<StaticStudy> s;
    {
      py::gil_scoped_release release;
      s = std::make_shared<StaticStudy>(static_study(*cs, n, r));
    }
    pyorigin::remember(s->model, *cs, n);
    return s;
  }, py::arg("case"), py::arg("n"), py::arg("rate"), py::arg("joint"));

  py::class_<ModesStudy, std::shared_ptr<ModesStudy>>(m, "ModesResult", "Natural frequencies and mode shapes (rfem.modes).", py::dynamic_attr())
      .def_property_readonly("n", [](const ModesStudy& s) { return s.model->n(); })
      .def_property_readonly("solver", [](const ModesStudy& s) { return s.modes.dense ? "dense" : "lanczos"; })
      .def_property_readonly("omega", [](const ModesStudy& s) { return vector_array(s.modes.omega); }, "[rad/s]")
      .def_property_readonly("frequencies", [](const ModesStudy& s) { return vector_array(s.modes.omega / (2 * M_PI)); }, "[Hz]")
      .def_property_readonly("kinds", [](const ModesStudy& s) {
        std::vector<std::string> k;
        for (ModeKind x : s.modes.kind) k.push_back(to_string(x));
        return k;
      }, "axial, bending-y, bending-z, torsion or rigid")
      .def_readonly("index_of_kind", &ModesStudy::index_of_kind)
      .def_property_readonly("shapes", [](const ModesStudy& s) { return py::array(py::cast(Eigen::MatrixXd(s.modes.shapes.transpose()))); },
                             "a row per mode (as modes/shapes in the file): the rfe coordinates, then the free joints' (M-normalised)")
      .def_property_readonly("equilibrium", [](const ModesStudy& s) { return vector_array(s.modes.q0); })
      .def_property_readonly("uncertainty", [](const ModesStudy& s) { return vector_array(s.modes.uncertainty); })
      .def_readonly("free_joints", &ModesStudy::free_names)
      .def_readonly("has_reference", &ModesStudy::has_reference)
      .def_property_readonly("reference", [](const ModesStudy& s) -> py::object {
        if (!s.has_reference) return py::none();
        py::list out;
        for (const auto& r : s.reference)
          out.append(py::dict(py::arg("hz") = r.reference_hz, py::arg("theory") = r.theory, py::arg("relative_error") = r.relative_error,
                              py::arg("euler_bernoulli_hz") = r.euler_bernoulli_hz ? py::cast(*r.euler_bernoulli_hz) : py::none()));
        return out;
      }, "Optional[list]: per mode, for one uniform segment, the exact value it converges to (None: no reference)")
      .def_readonly("warnings", &ModesStudy::warnings)
      .def_property_readonly("model", [](const ModesStudy& s) { return std::const_pointer_cast<Model>(s.model); })
      .def("__repr__", [](const ModesStudy& s) {
        std::string f;
        for (int i = 0; i < std::min<int>(3, static_cast<int>(s.modes.omega.size())); ++i)
          f += (f.empty() ? "" : ", ") + py::repr(py::float_(s.frequency_hz(i))).cast<std::string>();
        if (s.modes.omega.size() > 3) f += ", …";
        return "<rfem.ModesResult " + std::to_string(s.modes.omega.size()) + " modes, n=" + std::to_string(s.model->n()) +
               " rfes: " + f + " Hz>";
      });
  m.def("_modes", [](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"Optional[int]"> n, args::Typed<"int"> count, args::Typed<"Optional[List[Union[str, int]]]"> free, args::Typed<"Optional[float]"> rate, args::Typed<"int"> joint,
                     args::Typed<"Optional[Union[str, os.PathLike]]"> output_arg) {
    const args::CaseArg cs_arg(case_arg);
    const Case& cs = *cs_arg;
    ModesRequest rq;
    rq.n = args::rfes(n);
    rq.count = args::positive(count, "count");
    rq.free = args::free_joints(free);
    rq.rate = args::joint_rate(rate, joint);
    const std::string output = args::path(output_arg, "output", true);
    const std::string made_by = output.empty() ? "" : python_made_by("rfem.modes");
    py::gil_scoped_release release;
    auto s = std::make_shared<ModesStudy>(modes_into_file(cs, rq, output, made_by, 1));
    pyorigin::remember(s->model, cs, rq.n);  // (C++ only: no GIL needed)
    return s;
  }, py::arg("case"), py::arg("n"), py::arg("count"), py::arg("free"), py::arg("rate"), py::arg("joint"), py::arg("output"));

  m.def("_refine", [](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"List[int]"> ns, args::Typed<"List[str]"> quantity_args, args::Typed<"Optional[Union[str, os.PathLike]]"> output_arg,
                      args::Typed<"bool"> integration_check, args::Typed<"Optional[float]"> rate, args::Typed<"int"> joint, args::Typed<"int"> threads, args::Typed<"Optional[Callable[[dict], Any]]"> progress,
                      args::Typed<"Optional[List[int]]"> modes, args::Typed<"Optional[List[str]]"> accuracy, args::Typed<"Optional[int]"> max_n,
                      args::Typed<"Optional[float]"> max_time) {
    const args::CaseArg cs_arg(case_arg);
    const Case& cs = *cs_arg;
    const std::vector<std::string> quantities = args::texts(quantity_args, "quantities");
    const std::string output = args::path(output_arg, "output", true);
    auto pending = std::make_shared<CallGuard>();
    pending->progress = args::callback(progress, "progress");
    RefineRequest rq;
    if (!ns.is_none()) rq.ns = args::rfes_list(ns, "ns");
    if (!modes.is_none()) rq.modes = args::rfes_list(modes, "modes");
    rq.quantities = quantities;
    // A target (as rfem refine): accuracy=, or the case's [accuracy] for a study without a ladder of its own.
    const std::vector<std::string> given = accuracy.is_none() ? std::vector<std::string>{} : args::texts(accuracy, "accuracy");
    const AccuracySpec target =
        target_of(cs, given, 0, max_n.is_none() ? 0 : args::rfes(max_n, "max_n"), args::seconds(max_time, "max_time"), true);
    if (target.given() && (!given.empty() || (rq.modes.empty() && rq.ns.size() < 2))) apply_target(cs, target, rq);
    rq.integration_check = args::flag(integration_check, "integration_check");
    rq.rate = args::joint_rate(rate, joint);
    rq.threads = args::threads(threads);
    rq.stop = pending->stop;
    rq.progress = [pending](const Progress& p) { pending->beat(&p); };
    rq.on_n = [pending](int, int, int) { pending->beat(nullptr); };
    std::vector<std::string> warnings;
    rq.warn = [&warnings](const std::string& w) { warnings.push_back(w); };
    RefineResult res;
    {
      const std::string made_by = output.empty() ? "" : python_made_by("rfem.refine");
      py::gil_scoped_release release;
      res = output.empty() ? refine(cs, rq) : refine_into_file(cs, rq, output, made_by);
    }
    py::dict out;
    out["status"] = res.status.to_string();
    out["ns"] = res.ns;
    out["modes"] = res.modes;
    if (!res.allowed.empty()) {  // (a target)
      out["accuracy"] = rq.accuracy ? py::cast(*rq.accuracy) : py::none();
      out["met"] = res.met;
      out["shortfall"] = res.shortfall;
      out["rtol"] = res.rtol;
      out["atol"] = res.atol;
      out["calibration"] = res.calibration;
      out["time_limit"] = res.time_limit;
    }
    py::list tables;
    for (size_t k = 0; k < res.tables.size(); ++k) {
      const Refinement& t = res.tables[k];
      std::vector<int> n;
      for (const auto& r : t.rows) n.push_back(r.n);
      py::dict d;
      d["quantity"] = res.quantities[k].text;
      d[res.modes.empty() ? "n" : "modes"] = py::array(py::cast(n));
      for (auto [name, field] : {std::pair{"value", &RefinementRow::value}, {"change", &RefinementRow::change},
                                 {"order", &RefinementRow::order}, {"richardson", &RefinementRow::richardson}})
        d[name] = py::array(py::cast(t.column(field)));
      d["fitted_order"] = t.fitted_order;
      d["integration_error"] = t.integration_error;
      d["error"] = t.error;
      d["error_space"] = t.error_space;
      d["error_time"] = t.error_time;
      d["observed_order"] = t.observed_order();
      d["asymptotic"] = t.asymptotic;
      d["reference"] = t.reference();
      d["warnings"] = t.warnings;
      if (k < res.allowed.size()) d["allowed"] = res.allowed[k];
      tables.append(d);
    }
    out["tables"] = tables;
    out["warnings"] = warnings;
    py::object error = pending->take();
    return py::make_tuple(out, error);
  }, py::arg("case"), py::arg("ns"), py::arg("quantities"), py::arg("output"), py::arg("integration_check"),
     py::arg("rate"), py::arg("joint"), py::arg("threads"), py::arg("progress"), py::arg("modes"), py::arg("accuracy"),
     py::arg("max_n"), py::arg("max_time"));
  bind_sweep(m);
  bind_simulation(m);
  bind_accuracy(m);
}
