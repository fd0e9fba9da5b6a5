#pragma once
// Arguments from Python, checked as the program checks its options: a wrong type is a TypeError, a
// wrong value a ValueError, each one line naming the argument ("n: must be a positive integer up to
// 10000000 (got 0)"), never pybind11's "incompatible function arguments" dump, an int overflow or a
// bad_alloc later. Every binding takes its arguments as objects and converts them here; the limits
// are the library's (kMaxRfes, the case file's own). Strings with a NUL are refused: C++ would read
// "a\0b" as "a".
#include <pybind11/pybind11.h>

#include <climits>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "../cases/case_file.hpp"
#include "../simulation/common.hpp"

namespace rfem::pyargs {

namespace py = pybind11;

/// A type's text for the stubs (a template argument: Typed<"int | None">).
template <size_t N>
struct TypeText {
  char text[N];
  constexpr TypeText(const char (&t)[N]) {  // NOLINT: implicit, as a literal
    for (size_t i = 0; i < N; ++i) text[i] = t[i];
  }
};

/// An argument the binding checks itself (the functions below: one-line TypeError/ValueError naming
/// it), declared with the Python type its stub shows: pybind11 hands it over as the object it is.
template <TypeText T>
struct Typed {
  py::handle object;
  operator py::handle() const { return object; }  // NOLINT: implicit, to the checks below
  bool is_none() const { return object.is_none(); }
  PyObject* ptr() const { return object.ptr(); }
  template <typename U>
  U cast() const {
    return object.cast<U>();
  }
};

inline std::string type_name(py::handle v) { return py::str(py::type::of(v).attr("__name__")).cast<std::string>(); }
inline std::string shown(py::handle v) { return py::repr(v).cast<std::string>(); }

[[noreturn]] inline void type_error(const std::string& name, const std::string& what, py::handle v) {
  throw py::type_error(name + ": must be " + what + " (got " + type_name(v) + " " + shown(v) + ")");
}
[[noreturn]] inline void value_error(const std::string& name, const std::string& what, py::handle v) {
  throw py::value_error(name + ": must be " + what + " (got " + shown(v) + ")");
}

/// An integer lo..hi: a Python int or anything with __index__ (numpy's), not a bool or a float.
inline long integer(py::handle v, const std::string& name, long lo, long hi, const std::string& what) {
  if (PyBool_Check(v.ptr()) || !PyIndex_Check(v.ptr())) type_error(name, "an integer", v);
  const py::int_ i = py::reinterpret_steal<py::int_>(PyNumber_Index(v.ptr()));
  if (!i) {  // (numpy arrays have __index__ but refuse it unless 0-d)
    PyErr_Clear();
    type_error(name, "an integer", v);
  }
  int overflow = 0;
  const long long x = PyLong_AsLongLongAndOverflow(i.ptr(), &overflow);
  if (overflow != 0 || x < lo || x > hi) value_error(name, what, v);
  return static_cast<long>(x);
}

/// 1..hi, as the program's positive-integer options.
inline int positive(py::handle v, const std::string& name, long hi = INT_MAX) {
  return static_cast<int>(integer(v, name, 1, hi, "a positive integer up to " + std::to_string(hi)));
}

/// rfes in all links: None is the case's own discretisation (0), else 1..kMaxRfes (as --n).
inline int rfes(py::handle v, const std::string& name = "n") { return v.is_none() ? 0 : positive(v, name, kMaxRfes); }

/// Set in a child forked from a process that imported rfem (os.register_at_fork): GNU OpenMP's
/// thread pool does not survive fork, and a team of two there waits forever.
inline bool& forked() {
  static bool f = false;
  return f;
}

/// A team size: 0 (OpenMP's default, all cores) or a positive integer; at most 1 in a forked child.
inline int threads(py::handle v, const std::string& name = "threads") {
  const int t = static_cast<int>(integer(v, name, 0, INT_MAX, "0 (all cores) or a positive integer"));
  if (t > 1 && forked())
    value_error(name, "0 or 1 in a process forked from one that imported rfem (OpenMP's threads do not survive fork: "
                      "use multiprocessing's 'spawn' or 'forkserver' start method for more)", v);
  return t;
}

/// Whether v is one real number: a Python int or float, or a numpy scalar or 0-d array of an integer
/// or floating type (float32 too); not a bool, a string or an array of several values.
inline bool is_real(py::handle v) {
  if (PyBool_Check(v.ptr())) return false;
  if (PyFloat_Check(v.ptr())) return true;  // (numpy's float64 too)
  // numpy's scalars and arrays first: an array has __index__ too (which fails unless it is one integer)
  if (!py::hasattr(v, "dtype") || !py::hasattr(v, "ndim")) return PyIndex_Check(v.ptr());
  try {
    const std::string kind = py::str(v.attr("dtype").attr("kind")).cast<std::string>();
    return v.attr("ndim").cast<long>() == 0 && (kind == "f" || kind == "i" || kind == "u");
  } catch (const py::error_already_set&) {
    return false;
  }
}

/// A real number: int or float (numpy's too), not a bool or a string; finite unless allowed.
inline double real(py::handle v, const std::string& name, const std::string& what = "a finite number") {
  if (!is_real(v)) type_error(name, "a number", v);
  double x = NAN;
  try {
    x = py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
  } catch (const py::error_already_set&) {  // an int beyond a double's range
  }
  if (!std::isfinite(x)) value_error(name, what, v);
  return x;
}

/// A finite real ≥ 0 (checkpoint intervals: 0 is none).
inline double non_negative(py::handle v, const std::string& name, const std::string& what) {
  const double x = real(v, name, what);
  if (x < 0) value_error(name, what, v);
  return x;
}

/// None (0: no limit) or a positive, finite number of seconds.
inline double seconds(py::handle v, const std::string& name) {
  if (v.is_none()) return 0.0;
  const double x = real(v, name, "a positive number of seconds");
  if (!(x > 0)) value_error(name, "a positive number of seconds", v);
  return x;
}

/// None or a finite real.
inline std::optional<double> optional_real(py::handle v, const std::string& name, const std::string& what = "a finite number") {
  if (v.is_none()) return std::nullopt;
  return real(v, name, what);
}

inline bool flag(py::handle v, const std::string& name) {
  if (!PyBool_Check(v.ptr()) && type_name(v) != "bool_" && type_name(v) != "bool") type_error(name, "True or False", v);  // (numpy's too)
  return PyObject_IsTrue(v.ptr()) == 1;
}

inline std::string no_nul(std::string s, const std::string& name, py::handle v) {
  if (s.find('\0') != std::string::npos) value_error(name, "text without a NUL character", v);
  return s;
}

/// A str, without NUL.
inline std::string text(py::handle v, const std::string& name) {
  if (!PyUnicode_Check(v.ptr())) type_error(name, "a string", v);
  return no_nul(v.cast<std::string>(), name, v);
}

/// A file path: str, bytes or os.PathLike (os.fspath), without NUL; with `optional`, None or ""
/// is "" (no file).
inline std::string path(py::handle v, const std::string& name, bool optional = false) {
  if (optional && v.is_none()) return "";
  if (!PyUnicode_Check(v.ptr()) && !PyBytes_Check(v.ptr()) && !py::hasattr(v, "__fspath__"))
    type_error(name, optional ? "a path (str or os.PathLike) or None" : "a path (str or os.PathLike)", v);
  const py::object os = py::module_::import("os");
  const std::string s = no_nul(os.attr("fsdecode")(os.attr("fspath")(v)).cast<std::string>(), name, v);
  if (s.empty() && !optional) value_error(name, "a path, not empty", v);
  return s;
}

/// A list (any iterable but a single str, which is one item) of strings; None is none.
inline std::vector<std::string> texts(py::handle v, const std::string& name) {
  std::vector<std::string> out;
  if (v.is_none()) return out;
  if (PyUnicode_Check(v.ptr())) return {text(v, name)};
  if (!py::isinstance<py::iterable>(v)) type_error(name, "a list of strings", v);
  for (py::handle x : py::reinterpret_borrow<py::iterable>(v)) out.push_back(text(x, name + "[" + std::to_string(out.size()) + "]"));
  return out;
}

/// A list (any iterable) of rfe counts, each 1..kMaxRfes.
inline std::vector<int> rfes_list(py::handle v, const std::string& name) {
  if (PyUnicode_Check(v.ptr()) || !py::isinstance<py::iterable>(v)) type_error(name, "a list of integers", v);
  std::vector<int> out;
  for (py::handle x : py::reinterpret_borrow<py::iterable>(v)) out.push_back(positive(x, name + "[" + std::to_string(out.size()) + "]", kMaxRfes));
  return out;
}

/// None or a callable.
inline py::object callback(py::handle v, const std::string& name) {
  if (!v.is_none() && !PyCallable_Check(v.ptr())) type_error(name, "callable or None", v);
  return py::reinterpret_borrow<py::object>(v);
}

/// An object of a bound class (rfem.Case, rfem.Sweep, …), by reference for the call.
template <class T>
const T& object(py::handle v, const std::string& name, const std::string& what) {
  if (!py::isinstance<T>(v)) type_error(name, what, v);
  return v.cast<const T&>();
}

/// A case argument: an rfem.Case, or the path of a case file read here (CaseError if it cannot be).
class CaseArg {
 public:
  explicit CaseArg(py::handle v, const std::string& name = "case") {
    if (py::isinstance<Case>(v)) {
      case_ = &v.cast<const Case&>();
      return;
    }
    if (!PyUnicode_Check(v.ptr()) && !PyBytes_Check(v.ptr()) && !py::hasattr(v, "__fspath__"))
      type_error(name, "an rfem.Case or a case file's path", v);
    loaded_ = read_case(path(v, name));
    case_ = &*loaded_;
  }
  CaseArg(const CaseArg&) = delete;
  CaseArg& operator=(const CaseArg&) = delete;
  const Case& operator*() const { return *case_; }
  const Case* operator->() const { return case_; }

 private:
  std::optional<Case> loaded_;
  const Case* case_ = nullptr;
};

// `free` of rfem.modes: joint names or numbers from 1 (as --free), one or a list.
inline std::vector<std::string> free_joints(py::handle v) {
  std::vector<std::string> out;
  auto one = [&](py::handle x, const std::string& name) {
    if (PyUnicode_Check(x.ptr()) || PyBool_Check(x.ptr()) || !PyIndex_Check(x.ptr())) {
      if (!PyUnicode_Check(x.ptr())) type_error(name, "a joint's name or number from 1", x);
      out.push_back(text(x, name));
    } else {
      out.push_back(std::to_string(positive(x, name)));
    }
  };
  if (v.is_none()) return out;
  if (PyUnicode_Check(v.ptr()) || !py::isinstance<py::iterable>(v)) {
    one(v, "free");
    return out;
  }
  for (py::handle x : py::reinterpret_borrow<py::iterable>(v)) one(x, "free[" + std::to_string(out.size()) + "]");
  return out;
}

/// A steady joint rate (rfem.static, rfem.modes, rfem.refine: rate=, joint=).
inline JointRate joint_rate(py::handle rate, py::handle joint) {
  const std::optional<double> x = optional_real(rate, "rate", "a finite rate [rad/s or m/s] or None");
  JointRate r;
  r.given = x.has_value();
  r.rate = x.value_or(0.0);
  r.joint = positive(joint, "joint");
  return r;
}

}  // namespace rfem::pyargs

namespace pybind11::detail {
template <rfem::pyargs::TypeText T>
struct type_caster<rfem::pyargs::Typed<T>> {
  PYBIND11_TYPE_CASTER(rfem::pyargs::Typed<T>, const_name(T.text));
  bool load(handle src, bool) {
    value.object = src;
    return static_cast<bool>(src);
  }
  static handle cast(const rfem::pyargs::Typed<T>& v, return_value_policy, handle) { return v.object.inc_ref(); }
};
}  // namespace pybind11::detail
