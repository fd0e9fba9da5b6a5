// A target accuracy from Python (rfem.run, rfem.modes, rfem.static with accuracy=): the library
// chooses n and the tolerances (studies/accuracy.hpp); the wrappers in rfem/__init__.py then run
// the call there and attach this Accuracy (each value with its error bar).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "../studies/accuracy.hpp"
#include "../studies/reduction_error.hpp"
#include "arguments.hpp"
#include "call_guard.hpp"

namespace py = pybind11;
using namespace rfem;
namespace args = rfem::pyargs;
using rfem::pyguard::CallGuard;

namespace {

py::dict estimate_dict(const Estimate& e) {
  py::dict d;
  d["quantity"] = e.quantity;
  d["value"] = e.value;
  d["error"] = e.error;
  d["error_space"] = e.error_space;
  d["error_time"] = e.error_time;
  d["error_reduction"] = e.error_reduction;
  d["observed_order"] = e.observed_order;
  d["asymptotic"] = e.asymptotic;
  d["zero"] = e.zero;
  d["allowed"] = e.allowed;
  d["met"] = e.met();
  return d;
}

}  // namespace

void bind_accuracy(py::module_& m) {
  py::class_<AccuracyResult, std::shared_ptr<AccuracyResult>>(
      m, "Accuracy",
      "What a target accuracy chose and what it achieved (accuracy= on rfem.run, rfem.modes, rfem.static): n, the "
      "tolerances, and per value its error bar; acc[\"peak:run/u1\"] is one value's dict (value, error, error_space, "
      "error_time, error_reduction, observed_order, asymptotic, zero, allowed, met).")
      .def_readonly("n", &AccuracyResult::n)
      .def_readonly("rtol", &AccuracyResult::rtol, "the chosen tolerances (NaN: no time integration)")
      .def_readonly("atol", &AccuracyResult::atol)
      .def_readonly("met", &AccuracyResult::met, "every value met its target")
      .def_readonly("shortfall", &AccuracyResult::shortfall, "per value that missed it: why and by how much")
      .def_readonly("calibration", &AccuracyResult::calibration, "how the tolerances were chosen, a line per try")
      .def_readonly("warnings", &AccuracyResult::warnings)
      .def_property_readonly("relative", [](const AccuracyResult& a) { return a.target.relative; }, "the relative target (0: none)")
      .def_property_readonly("estimates", [](const AccuracyResult& a) {
        py::list out;
        for (const Estimate& e : a.estimates) out.append(estimate_dict(e));
        return out;
      }, "one dict per value, in the order the command reports them")
      .def("__getitem__", [](const AccuracyResult& a, const std::string& q) {
        const Estimate* e = a.find(q);
        if (!e) {
          std::string have;
          for (const Estimate& x : a.estimates) have += (have.empty() ? "" : ", ") + x.quantity;
          throw py::key_error("no value named '" + q + "' (have " + have + ")");
        }
        return estimate_dict(*e);
      })
      .def("__len__", [](const AccuracyResult& a) { return a.estimates.size(); })
      .def("__repr__", [](const AccuracyResult& a) {
        return "<rfem.Accuracy " + std::string(a.met ? "met" : "NOT met") + " at n=" + std::to_string(a.n) + ", " +
               std::to_string(a.estimates.size()) + " values>";
      });

  m.def("_accuracy", [](args::Typed<"Union[Case, str, os.PathLike]"> case_arg, args::Typed<"str"> command_arg,
                        args::Typed<"Optional[List[str]]"> accuracy, args::Typed<"Optional[int]"> max_n,
                        args::Typed<"Optional[float]"> max_time, args::Typed<"Optional[int]"> n_arg,
                        args::Typed<"int"> count, args::Typed<"Optional[float]"> rate, args::Typed<"int"> joint,
                        args::Typed<"int"> threads, args::Typed<"Optional[Callable[[dict], Any]]"> progress,
                        args::Typed<"Optional[List[Union[str, int]]]"> free) {
    const args::CaseArg cs_arg(case_arg);
    const Case& cs = *cs_arg;
    const std::string command = py::str(command_arg);
    const std::vector<std::string> given = accuracy.is_none() ? std::vector<std::string>{} : args::texts(accuracy, "accuracy");
    const AccuracySpec target = target_of(cs, given, args::rfes(n_arg), max_n.is_none() ? 0 : args::rfes(max_n, "max_n"),
                                          args::seconds(max_time, "max_time"));
    if (!target.given()) return py::make_tuple(py::none(), py::none());
    Reported reported;
    RefineRequest base;
    base.rate = args::joint_rate(rate, joint);
    base.free = args::free_joints(free);
    if (command == "run") reported = reported_by_run(cs);
    else if (command == "modes") reported = reported_by_modes(args::positive(count, "count"));
    else if (command == "static") reported = reported_by_static(cs, base.rate);
    else if (command == "linearize") reported = reported_by_linearize(6);
    else throw py::value_error("command: run, modes, static or linearize");
    auto pending = std::make_shared<CallGuard>();
    pending->progress = args::callback(progress, "progress");
    base.threads = args::threads(threads);
    base.stop = pending->stop;
    base.progress = [pending](const Progress& p) { pending->beat(&p); };
    base.on_n = [pending](int, int, int) { pending->beat(nullptr); };
    std::vector<std::string> warnings;
    base.warn = [&warnings](const std::string& w) { warnings.push_back(w); };
    std::shared_ptr<AccuracyResult> a;
    {
      py::gil_scoped_release release;
      a = std::make_shared<AccuracyResult>(meet_accuracy(cs, target, reported, base));
    }
    a->warnings.insert(a->warnings.end(), warnings.begin(), warnings.end());
    py::object error = pending->take();  // (Ctrl-C: rfem._raise turns it into RunInterrupted)
    return py::make_tuple(py::cast(a), error);
  }, py::arg("case"), py::arg("command"), py::arg("accuracy"), py::arg("max_n"), py::arg("max_time"), py::arg("n"), py::arg("count"), py::arg("rate"),
     py::arg("joint"), py::arg("threads"), py::arg("progress"), py::arg("free") = py::none());

  m.def("_add_reduction_error", [](AccuracyResult& a, const std::vector<std::shared_ptr<RunResult>>& runs) {
    std::vector<RunResult> rs;
    for (const auto& r : runs)
      if (r) rs.push_back(*r);
    add_reduction_error(a, rs);
  }, py::arg("accuracy"), py::arg("runs"));

  m.def("_write_accuracy", [](args::Typed<"Union[str, os.PathLike]"> path, const AccuracyResult& a) {
    const std::string p = args::path(path, "output");
    py::gil_scoped_release release;
    write_accuracy(p, a);
  }, py::arg("path"), py::arg("accuracy"));
}
