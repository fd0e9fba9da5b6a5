// rfem.Simulation (a run a script steps) and rfem.run(controller=…) for Python. The integration
// runs with the GIL released; a heartbeat takes it back to poll Ctrl-C, and a Python controller
// takes it for its call only. Python's package (python/rfem/simulation.py) wraps these.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <memory>

#include "arguments.hpp"
#include "call_guard.hpp"
#include "pickling.hpp"
#include <pybind11/eigen.h>

#include "../results/writer.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../simulation/simulation.hpp"
#include "../studies/resume.hpp"
#include "../studies/run_file.hpp"

namespace py = pybind11;
using namespace rfem;
namespace args = rfem::pyargs;

namespace {

using Poll = pyguard::CallGuard;

py::array_t<double> array(const VecX& v) { return py::array_t<double>(v.size(), v.data()); }

py::dict snapshot_dict(const Snapshot& y, const Model& model) {
  py::dict q, qd, tau, tip, defl;
  for (int j = 0; j < model.m(); ++j) {
    const py::str name(model.joints[j].name);
    q[name] = y.joint_q[j];
    qd[name] = y.joint_v[j];
    tau[name] = y.joint_tau[j];
  }
  for (size_t l = 0; l < model.links.size(); ++l) {
    const py::str name(model.links[l].name);
    tip[name] = py::array_t<double>(3, y.tip_position[l].data());
    defl[name] = py::array_t<double>(3, y.tip_deflection[l].data());
  }
  py::dict d;
  d["t"] = y.t;
  d["q"] = q;
  d["qd"] = qd;
  d["tau"] = tau;
  d["tip_position"] = tip;
  d["tip_deflection"] = defl;
  for (const auto& [name, values] : y.sensors)  // (a case's sensor names never clash with these keys)
    if (values.size() == 1) d[py::str(name)] = values[0];
    else d[py::str(name)] = py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data());
  return d;
}

// The options of rfem.Simulation and rfem.run_controlled, their arguments checked (arguments.hpp).
SimulationOptions options(py::handle n, py::handle threads, py::handle output, py::handle keep_series,
                          std::optional<SimulationState> state, const std::string& made_by, const std::shared_ptr<Poll>& poll) {
  SimulationOptions o;
  o.n = args::rfes(n);
  o.threads = args::threads(threads);
  o.output = args::path(output, "output", true);
  o.keep_series = args::flag(keep_series, "keep_series");
  o.made_by = made_by;
  o.driven_by = made_by;  // (a script's run: its inputs are the script's)
  if (state) o.state = std::make_shared<const SimulationState>(std::move(*state));
  o.stop = poll->stop;
  o.progress = [poll](const Progress&) { poll->beat(nullptr); };
  o.progress_interval = 0.1;
  return o;
}

// One Python value of a controller's dict for joint `name` of input kind `kind`.
void control_value(ControlOutput& u, const std::string& name, const std::string& kind, const py::handle& v, Poll& poll) {
  auto bad = [&](PyObject* type, const std::string& msg) {
    poll.bad = py::reinterpret_borrow<py::object>(type)(msg);
    throw std::invalid_argument(msg);
  };
  auto number = [&](const py::handle& x) {
    if (!args::is_real(x)) {
      std::string got = args::type_name(x);
      if (py::hasattr(x, "shape")) got += " of shape " + py::str(x.attr("shape")).cast<std::string>();
      bad(PyExc_TypeError, "joint '" + name + "': expected a number, got " + got);
    }
    double y = NAN;
    try {
      y = py::float_(py::reinterpret_borrow<py::object>(x)).cast<double>();
    } catch (const py::error_already_set&) {  // (an int beyond a double's range)
    }
    return y;  // (not finite: refused by the loop, a ValueError)
  };
  if (kind == "motion") bad(PyExc_ValueError, "joint '" + name + "' follows a prescribed motion: it takes no torque or reference");
  if (kind == "torque") {
    u.torques[name] = number(v);
    return;
  }
  ControlOutput::Reference r;  // feedback: q_ref, or (q_ref, q̇_ref[, τ_ff])
  if (py::isinstance<py::tuple>(v) || py::isinstance<py::list>(v)) {
    const py::sequence s = py::reinterpret_borrow<py::sequence>(v);
    if (s.size() < 1 || s.size() > 3) bad(PyExc_ValueError, "joint '" + name + "': a reference is q_ref or (q_ref, qd_ref[, tau_ff])");
    r.q = number(s[0]);
    if (s.size() > 1) r.v = number(s[1]);
    if (s.size() > 2) r.tau_ff = number(s[2]);
  } else {
    r.q = number(v);
  }
  u.references[name] = r;
}

}  // namespace

void bind_simulation(py::module_& m) {
  py::class_<SimulationState>(m, "SimulationState",
                              "A simulation's state (rfem.Simulation.state()): start other simulations from it, save it, pickle it.")
      .def_property_readonly("time", &SimulationState::time, "[s]")
      .def_readonly("model", &SimulationState::model, "the signature of the model it belongs to")
      .def_property_readonly("unknowns_q", [](const SimulationState& s) { return array(s.integrator.q); },
                             "the integrated coordinates (rfes, then the force-input joints)")
      .def_property_readonly("unknowns_v", [](const SimulationState& s) { return array(s.integrator.v); })
      .def("pack", [](const SimulationState& s) { const auto x = s.pack(); return py::array_t<double>(x.size(), x.data()); },
           "the state as one float64 array (with .model, what unpack takes)")
      .def_static("unpack", [](const std::string& model, const py::array_t<double, py::array::c_style | py::array::forcecast>& x) {
        if (x.ndim() != 1) throw py::value_error("packed: a 1-D array of numbers (SimulationState.pack()), not " +
                                                 std::to_string(x.ndim()) + "-D");
        return SimulationState::unpack(model, std::vector<double>(x.data(), x.data() + x.size()));
      }, py::arg("model"), py::arg("packed"))
      .def("save", [](const SimulationState& s, args::Typed<"Union[str, os.PathLike]"> path) { save_state(s, args::path(path, "path")); }, py::arg("path"),
           "into an HDF5 file of its own (state/packed, state/model)")
      .def_static("load", [](args::Typed<"Union[str, os.PathLike]"> path) { return read_state(args::path(path, "path")); }, py::arg("path"),
                  "a state file (save) or a single run's results file: its newest checkpoint (an interrupted or killed run's)")
      .def(py::pickle([](const SimulationState& s) { return py::make_tuple(s.model, s.pack()); },
                      [](const py::tuple& t) {
                        if (t.size() != 2 || !PyUnicode_Check(t[0].ptr()))
                          throw py::value_error("not a pickled rfem.SimulationState");
                        std::vector<double> x;
                        try {
                          x = t[1].cast<std::vector<double>>();
                        } catch (const py::cast_error&) {
                          throw py::value_error("not a pickled rfem.SimulationState: its values are not numbers");
                        }
                        return SimulationState::unpack(t[0].cast<std::string>(), x);
                      }))
      .def("__repr__", [](const SimulationState& s) {
        return "<rfem.SimulationState t = " + std::to_string(s.time()) + " s, " + std::to_string(s.integrator.q.size()) + " unknowns>";
      });

  // A Simulation is used by one thread at a time: a second thread that enters while the first is in
  // a call (advance releases the GIL) gets a RuntimeError instead of a data race.
  struct PySimulation {
    std::shared_ptr<Poll> poll = std::make_shared<Poll>();
    std::unique_ptr<Simulation> sim;
    mutable std::atomic<bool> busy{false};
  };
  struct Use {
    const PySimulation& p;
    Use(const PySimulation& q, const char* what) : p(q) {
      if (p.busy.exchange(true))
        throw std::runtime_error(std::string("rfem.Simulation.") + what + ": the simulation is in use by another thread "
                                 "(one thread at a time: a lock of your own around its calls)");
    }
    ~Use() { p.busy.store(false); }
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;
    Simulation* operator->() const { return p.sim.get(); }
    Simulation& operator*() const { return *p.sim; }
  };
  // (declared before the simulation that returns it: the signatures name it)
  py::class_<LinearModel, std::shared_ptr<LinearModel>> linear_model(
      m, "LinearModel",
      "A linear model about a state (rfem.linearize, Simulation.linearize): M q'' + D q' + K q = B u, "
      "y = Cq q + Cv q' + Ca q'' (deviations from the operating point; SI units, rows and columns named by "
      "states, inputs, outputs); state_space() gives A, B, C, D of x = (q, q').", py::dynamic_attr());
  py::class_<PySimulation>(m, "_Simulation")
      .def(py::init([](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"Optional[int]"> n, args::Typed<"int"> threads, args::Typed<"Optional[Union[str, os.PathLike]]"> output, args::Typed<"bool"> keep_series,
                       std::optional<SimulationState> state, const std::string& made_by) {
             const args::CaseArg cs(case_arg);
             auto p = std::make_unique<PySimulation>();
             SimulationOptions o = options(n, threads, output, keep_series, std::move(state), made_by, p->poll);
             const int n_rfes = o.n;
             py::gil_scoped_release release;
             p->sim = std::make_unique<Simulation>(*cs, std::move(o));
             pyorigin::remember(p->sim->shared_model(), *cs, n_rfes);
             return p;
           }),
           py::arg("case"), py::arg("n"), py::arg("threads"), py::arg("output"), py::arg("keep_series"), py::arg("state"),
           py::arg("made_by"))
      .def_property_readonly("time", [](const PySimulation& p) { return Use(p, "time")->time(); })
      .def_property_readonly("t_end", [](const PySimulation& p) { return Use(p, "t_end")->t_end(); })
      .def_property_readonly("q", [](const PySimulation& p) { return array(Use(p, "q")->q()); })
      .def_property_readonly("v", [](const PySimulation& p) { return array(Use(p, "v")->v()); })
      .def_property_readonly("coordinate_names", [](const PySimulation& p) { return Use(p, "coordinate_names")->coordinate_names(); })
      .def_property_readonly("joint_names", [](const PySimulation& p) { return Use(p, "joint_names")->joint_names(); })
      .def_property_readonly("joint_inputs", [](const PySimulation& p) { return Use(p, "joint_inputs")->joint_inputs(); })
      .def_property_readonly("status", [](const PySimulation& p) { return Use(p, "status")->status().to_string(); })
      .def_property_readonly("finished", [](const PySimulation& p) { return Use(p, "finished")->finished(); })
      .def_property_readonly("output", [](const PySimulation& p) { return Use(p, "output")->output(); })
      .def("set_torque", [](PySimulation& p, args::Typed<"str"> j, args::Typed<"float"> tau) {
        Use(p, "set_torque")->set_torque(args::text(j, "joint"), args::real(tau, "tau", "a finite torque [N m] or force [N]"));
      })
      .def("set_reference", [](PySimulation& p, args::Typed<"str"> j, args::Typed<"float"> q, args::Typed<"float"> v, args::Typed<"float"> ff) {
        Use(p, "set_reference")->set_reference(args::text(j, "joint"), args::real(q, "q"), args::real(v, "qd"), args::real(ff, "tau_ff"));
      })
      .def("release", [](PySimulation& p, args::Typed<"str"> j) { Use(p, "release")->release(args::text(j, "joint")); })
      .def("advance", [](PySimulation& p, args::Typed<"float"> time) {
        const double t = args::real(time, "t", "a finite time [s]");
        RunStatus s;
        {
          const Use use(p, "advance");
          py::gil_scoped_release release;
          s = use->advance(t);
        }
        py::object error = p.poll->take();
        return py::make_tuple(s.to_string(), error);
      })
      .def("snapshot", [](PySimulation& p) {
        const Use use(p, "snapshot");
        return snapshot_dict(use->snapshot(), use->model());
      })
      .def("state", [](const PySimulation& p) { return Use(p, "state")->state(); })
      .def("linearize", [](PySimulation& p, args::Typed<"bool"> equilibrium, args::Typed<"bool"> dense) {
        const bool eq = args::flag(equilibrium, "equilibrium"), d = args::flag(dense, "dense");
        const Use use(p, "linearize");
        py::gil_scoped_release release;
        return std::make_shared<LinearModel>(linearize(*use, eq, d));
      }, py::arg("equilibrium"), py::arg("dense"))
      .def("finish", [](PySimulation& p) {
        std::shared_ptr<RunResult> r;
        {
          const Use use(p, "finish");
          py::gil_scoped_release release;
          r = std::make_shared<RunResult>(use->finish());
        }
        return r;
      });

  linear_model
      .def_readonly("t", &LinearModel::t, "the state's time [s]")
      .def_readonly("equilibrium", &LinearModel::equilibrium, "about rest (q'' = 0) or the motion")
      .def_readonly("states", &LinearModel::states, "List[str]: the unknowns, rfe coordinates LINK/rfeK/x1 … phi3, free joints")
      .def_readonly("inputs", &LinearModel::inputs, "List[str]: free joints, a torque [N m] (force [N]) added to each")
      .def_readonly("outputs", &LinearModel::outputs, "LINK/tip_u1 … tip_theta, JOINT/q, v, tau, sensor columns")
      .def_readonly("output_units", &LinearModel::output_units)
      .def_property_readonly("M", [](const LinearModel& l) { return l.M; }, "states × states [kg, kg m, kg m²] (scipy.sparse CSC)")
      .def_property_readonly("D", [](const LinearModel& l) { return l.D; }, "states × states: damping, PD kd, gyroscopic (sparse)")
      .def_property_readonly("K", [](const LinearModel& l) { return l.K; }, "states × states: elastic, geometric, gravity, centrifugal, PD kp (sparse)")
      .def_property_readonly("B", [](const LinearModel& l) { return l.B; }, "states × inputs (sparse)")
      .def_readonly("evaluations", &LinearModel::evaluations, "evaluations of the equations it took")
      .def_property_readonly("Cq", [](const LinearModel& l) { return l.Cq; }, "outputs × states (dense)")
      .def_property_readonly("Cv", [](const LinearModel& l) { return l.Cv; }, "outputs × states (dense)")
      .def_property_readonly("Ca", [](const LinearModel& l) { return l.Ca; }, "outputs × states (dense)")
      .def_property_readonly("q0", [](const LinearModel& l) { return array(l.q0); }, "the operating point (states)")
      .def_property_readonly("v0", [](const LinearModel& l) { return array(l.v0); })
      .def_property_readonly("a0", [](const LinearModel& l) { return array(l.a0); })
      .def_property_readonly("u0", [](const LinearModel& l) { return array(l.u0); }, "the inputs that hold the state")
      .def_property_readonly("y0", [](const LinearModel& l) { return array(l.y0); }, "the outputs there")
      .def_readonly("imbalance", &LinearModel::imbalance, "the rfe rows' residual there, relative (≪ 1 at an equilibrium)")
      .def("state_space", [](const LinearModel& l) {
        MatX A, B, C, D;
        {
          py::gil_scoped_release release;
          l.state_space(A, B, C, D);
        }
        return py::make_tuple(A, B, C, D);
      }, "(A, B, C, D) of x' = A x + B u, y = C x + D u with x = (q, q'): 2N states, dense (up to 3000 states)")
      .def("descriptor", [](const LinearModel& l) {
        SparseMat E, A, B, C;
        {
          py::gil_scoped_release release;
          l.descriptor(E, A, B, C);
        }
        return py::make_tuple(E, A, B, C);
      }, "(E, A, B, C), scipy.sparse, of E x' = A x + B u, y = C x with x = (q, q', q''): 3N states, any size "
         "(E = diag(I, I, 0): the last block row is the equations of motion)")
      .def("modes", [](const LinearModel& l, int count) {
        std::vector<std::pair<double, double>> m;
        {
          py::gil_scoped_release release;
          m = linear_modes(l, count);
        }
        return m;
      }, py::arg("count") = 6, "the lowest modes of A: [(f [Hz], damping ratio)], one per oscillating pair")
      .def_property_readonly("first_order_states", &LinearModel::first_order_states)
      .def("__repr__", [](const LinearModel& l) {
        return "<rfem.LinearModel " + std::to_string(l.states.size()) + " states, " + std::to_string(l.inputs.size()) + " inputs, " +
               std::to_string(l.outputs.size()) + " outputs, about " + (l.equilibrium ? "rest" : "the motion") + " at t = " +
               py::repr(py::float_(l.t)).cast<std::string>() + " s>";
      });
  m.def("_linear_modes", [](const SparseMat& M, const SparseMat& D, const SparseMat& K, int count) {
    LinearModel l;  // (the modes need M, D and K only)
    l.M = M;
    l.D = D;
    l.K = K;
    py::gil_scoped_release release;
    return linear_modes(l, count);
  }, py::arg("M"), py::arg("D"), py::arg("K"), py::arg("count"));
  m.def("_linearize", [](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"Optional[int]"> n, args::Typed<"Optional[SimulationState]"> state, args::Typed<"int"> threads, args::Typed<"bool"> equilibrium,
                         args::Typed<"Optional[Union[str, os.PathLike]]"> output_arg, const std::string& made_by, args::Typed<"bool"> dense) {
    const args::CaseArg cs_arg(case_arg);
    const Case& cs = *cs_arg;
    LinearizeRequest rq;
    rq.n = args::rfes(n);
    rq.threads = args::threads(threads);
    rq.equilibrium = args::flag(equilibrium, "equilibrium");
    rq.dense = args::flag(dense, "dense");
    if (!state.is_none()) {
      if (!py::isinstance<SimulationState>(state)) args::type_error("state", "an rfem.SimulationState or None", state);
      rq.state = std::make_shared<const SimulationState>(state.cast<SimulationState>());
    }
    const std::string output = args::path(output_arg, "output", true);
    py::gil_scoped_release release;
    return std::make_shared<LinearModel>(linearize_into_file(cs, rq, output, made_by));
  }, py::arg("case"), py::arg("n"), py::arg("state"), py::arg("threads"), py::arg("equilibrium"), py::arg("output"), py::arg("made_by"), py::arg("dense"));

  m.def("_run_controlled", [](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"Optional[int]"> n, args::Typed<"int"> threads, args::Typed<"Optional[Union[str, os.PathLike]]"> output, args::Typed<"bool"> keep_series,
                              std::optional<SimulationState> state, const std::string& made_by, py::object controller,
                              args::Typed<"float"> sample_time, args::Typed<"int"> delay) {
    const args::CaseArg cs_arg(case_arg);
    const Case& cs = *cs_arg;
    if (!PyCallable_Check(controller.ptr())) args::type_error("controller", "callable f(t, y)", controller);
    auto poll = std::make_shared<Poll>();
    SimulationOptions o = options(n, threads, output, keep_series, std::move(state), made_by, poll);
    const std::vector<std::string> kinds = input_kinds(joint_inputs(cs));
    std::vector<std::string> names;
    for (const auto& j : cs.joints) names.push_back(j.name);
    std::shared_ptr<const Model> model;
    const Controller f = [&](double t, const Snapshot& y) {
      py::gil_scoped_acquire gil;
      ControlOutput u;
      if (!poll->signals()) return u;
      py::object r;
      try {
        r = controller(t, snapshot_dict(y, *model));
      } catch (py::error_already_set& e) {
        if (e.matches(PyExc_KeyboardInterrupt)) {
          poll->keep(e);
          return u;
        }
        // The run ends `failed: controller: TYPE: message`, the Python exception not raised again.
        throw std::runtime_error(py::str(e.type().attr("__name__")).cast<std::string>() + ": " + py::str(e.value()).cast<std::string>());
      }
      if (!py::isinstance<py::dict>(r)) {
        const std::string msg = "the controller must return a dict by joint name ({\"hub\": 1.5}), not " +
                                py::str(py::type::of(r).attr("__name__")).cast<std::string>();
        poll->bad = py::reinterpret_borrow<py::object>(PyExc_TypeError)(msg);
        throw std::invalid_argument(msg);
      }
      for (const auto& [k, v] : py::reinterpret_borrow<py::dict>(r)) {
        if (!py::isinstance<py::str>(k)) {
          const std::string msg = "the controller's dict must have joint names as keys";
          poll->bad = py::reinterpret_borrow<py::object>(PyExc_TypeError)(msg);
          throw std::invalid_argument(msg);
        }
        const std::string name = k.cast<std::string>();
        const auto it = std::find(names.begin(), names.end(), name);
        if (it == names.end()) {
          std::string known;
          for (const auto& x : names) known += (known.empty() ? "" : ", ") + x;
          const std::string msg = "no joint named '" + name + "' (joints: " + known + ")";
          poll->bad = py::reinterpret_borrow<py::object>(PyExc_ValueError)(msg);
          throw std::invalid_argument(msg);
        }
        control_value(u, name, kinds[static_cast<size_t>(it - names.begin())], v, *poll);
      }
      return u;
    };
    ControlOptions c;
    c.sample_time = args::real(sample_time, "sample_time", "a finite time [s]");
    c.delay = static_cast<int>(args::integer(delay, "delay", 0, INT_MAX, "a number of samples, 0 or more"));
    // A value the C++ loop refused (not finite) is a ValueError too (called with the GIL released).
    c.on_error = [poll](const ControllerError& e) {
      if (e.kind() != ControllerError::Kind::NotFinite) return;
      py::gil_scoped_acquire gil;
      if (poll->bad.is_none()) poll->bad = py::reinterpret_borrow<py::object>(PyExc_ValueError)(e.what());
    };
    std::shared_ptr<RunResult> result;
    {
      py::gil_scoped_release release;
      model = model_of(cs, o.n);  // (the snapshot's names; the same as the run's model)
      const int n_rfes = o.n;
      result = std::make_shared<RunResult>(run_controlled(cs, std::move(o), f, c));
      pyorigin::remember(result->model, cs, n_rfes);
    }
    return py::make_tuple(result, poll->error, poll->bad);
  }, py::arg("case"), py::arg("n"), py::arg("threads"), py::arg("output"), py::arg("keep_series"), py::arg("state"),
     py::arg("made_by"), py::arg("controller"), py::arg("sample_time"), py::arg("delay"));
}
