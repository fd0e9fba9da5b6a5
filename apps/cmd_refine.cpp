#include <fmt/core.h>

#include <cctype>
#include <cmath>
#include <memory>

#include "apps/simulate.hpp"
#include "solvers/modes.hpp"
#include "solvers/statics.hpp"

namespace rfem::app {

double evaluate_quantity(const Case& cs, int n, const std::string& quantity, const ModesOptions& o) {
  const Model model = build_model(cs, n);
  VecX qb, vb;
  joint_state(cs, o, qb, vb);
  const auto colon = quantity.find(':');
  const std::string what = quantity.substr(0, colon), arg = colon == std::string::npos ? "" : quantity.substr(colon + 1);
  if (what == "tip") {
    static const char* names[6] = {"ux", "uy", "uz", "rx", "ry", "rz"};
    for (int i = 0; i < 6; ++i)
      if (arg == names[i]) return tip_motion(model, solve_static(model, qb, vb, cs.loads).q)[i];
    throw CaseError("--quantity " + quantity + ": tip component must be ux, uy, uz, rx, ry or rz");
  }
  int k = 0;
  try {
    k = std::stoi(arg);
  } catch (...) {
    k = 0;
  }
  if (k < 1) throw CaseError("--quantity " + quantity + ": expected NAME:K with K ≥ 1");
  if (what != "mode" && what != "axial" && what != "bending-y" && what != "bending-z" && what != "torsion")
    throw CaseError("--quantity " + quantity + ": unknown quantity '" + what + "'");
  if (what == "mode") {
    if (k > 6 * model.n()) throw CaseError("--quantity " + quantity + ": n = " + std::to_string(n) + " has only " + std::to_string(6 * model.n()) + " modes");
    return compute_modes(model, qb, vb, k).omega[k - 1] / (2 * M_PI);
  }
  // Modes of one kind can sit high in the spectrum (axial modes of a slender beam): widen the
  // search until the k-th one appears.
  for (int count = std::min(6 * model.n(), 4 * k + 8);; count = std::min(6 * model.n(), 2 * count)) {
    const ModesResult r = compute_modes(model, qb, vb, count);
    int seen = 0;
    for (int i = 0; i < count; ++i)
      if (to_string(r.kind[i]) == what && ++seen == k) return r.omega[i] / (2 * M_PI);
    if (count == 6 * model.n()) break;
  }
  const int count = 6 * model.n();
  throw std::runtime_error("--quantity " + quantity + ": no such mode among all " + std::to_string(count) +
                           " at n = " + std::to_string(n));
}

namespace {

// A dynamic quantity "[RUN/]peak:u1|u2|theta", "[RUN/]u1@T", "u2@T", "theta@T", "tauJ@T", "qJ@T"
// (J 1-based). Returns false if `quantity` is not dynamic.
struct DynamicQuantity {
  std::string run, what;
  double time = -1.0;  // < 0: peak over the run
  int joint = -1;
};

bool parse_dynamic(const Case& cs, const std::string& quantity, DynamicQuantity& d) {
  std::string q = quantity;
  const auto slash = q.find('/');
  d.run = cs.sim.procedure == "paper" ? "kinematic" : "run";
  if (slash != std::string::npos) {
    d.run = q.substr(0, slash);
    q = q.substr(slash + 1);
  }
  if (q.rfind("peak:", 0) == 0) {
    d.what = q.substr(5);
  } else if (const auto at = q.find('@'); at != std::string::npos) {
    d.what = q.substr(0, at);
    try {
      d.time = std::stod(q.substr(at + 1));
    } catch (...) {
      throw CaseError("--quantity " + quantity + ": '" + q.substr(at + 1) + "' is not a time");
    }
  } else {
    return false;
  }
  if (d.what.rfind("tau", 0) == 0 || (d.what.size() > 1 && d.what[0] == 'q' && std::isdigit(d.what[1]))) {
    const std::string num = d.what.substr(d.what[0] == 'q' ? 1 : 3);
    d.joint = num.empty() ? 0 : std::atoi(num.c_str());
    if (d.joint < 1 || d.joint > static_cast<int>(cs.joints.size()))
      throw CaseError("--quantity " + quantity + ": joint must be 1.." + std::to_string(cs.joints.size()));
    d.what = d.what[0] == 'q' ? "q" : "tau";
  } else if (d.what != "u1" && d.what != "u2" && d.what != "theta") {
    throw CaseError("--quantity " + quantity + ": expected u1, u2, theta, tauJ or qJ");
  }
  if (!cs.has_simulation) throw CaseError(cs.path + ": simulation: a dynamic quantity needs a [simulation] table");
  return true;
}

double evaluate_dynamic(const Case& cs, const std::vector<JointInput>& inputs, int n, const DynamicQuantity& d,
                        ResultsFile& file, bool quiet) {
  const Model model = build_model(cs, n);
  const std::string prefix = fmt::format("n{}/", n);  // (fmt: GCC 12 warns falsely on "n" + to_string)
  double value = d.time < 0 ? 0.0 : NAN, best_dt = 1e300;
  auto observe = [&](const std::string& run, const Model& m, const OutputSample& s) {
    if (run != prefix + d.run) return;
    double x = 0.0;
    if (d.what == "tau") x = s.tau[d.joint - 1];
    else if (d.what == "q") x = s.q[6 * m.n() + d.joint - 1];
    else x = tip_deflection(m, s.q)[d.what == "u1" ? 0 : d.what == "u2" ? 1 : 2];
    if (d.time < 0) value = std::max(value, std::abs(x));
    else if (std::abs(s.t - d.time) < best_dt) best_dt = std::abs(s.t - d.time), value = x;
  };
  const auto runs = simulate_case(cs, model, inputs, file, prefix, quiet, observe);
  bool seen = false;
  for (const auto& r : runs) {
    if (!r.completed) throw std::runtime_error("n = " + std::to_string(n) + ": " + r.name + " " + r.status);
    seen |= r.name == prefix + d.run;
  }
  if (!seen) throw CaseError("--quantity: no run named '" + d.run + "' (runs: rigid, kinematic, force or run)");
  if (d.time >= 0 && best_dt > 1e-9 * std::max(1.0, d.time))
    throw CaseError("--quantity: t = " + std::to_string(d.time) + " s is not an output time (output_dt = " +
                    std::to_string(cs.sim.output_dt) + " s)");
  return value;
}

void write_table(ResultsFile& file, const std::string& quantity, const std::vector<int>& ns, const std::vector<double>& val,
                 const std::vector<double>& change, const std::vector<double>& order, const std::vector<double>& extrap) {
  const hid_t g = H5Gcreate2(file.id(), "refine", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  auto put = [&](const char* name, const std::vector<double>& v) {
    const hsize_t dims[1] = {v.size()};
    const hid_t sp = H5Screate_simple(1, dims, nullptr);
    const hid_t ds = H5Dcreate2(g, name, H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(ds);
    H5Sclose(sp);
  };
  put("n", std::vector<double>(ns.begin(), ns.end()));
  put("value", val);
  put("change", change);
  put("order", order);
  put("richardson", extrap);
  write_attribute(g, "quantity", quantity);
  if (std::isfinite(extrap.back())) write_attribute(g, "reference", extrap.back());
  H5Gclose(g);
  file.flush();
}

}  // namespace

int run_refine(const Common& c, const std::vector<int>& ns, const std::string& quantity, const ModesOptions& o,
               const std::string& output) {
  const Case cs = read_case(c.case_path, c.overrides);
  DynamicQuantity dq;
  const bool dynamic = parse_dynamic(cs, quantity, dq);
  std::unique_ptr<ResultsFile> file;
  const std::vector<JointInput> inputs = dynamic ? joint_inputs(cs) : std::vector<JointInput>{};
  if (dynamic || !output.empty()) {
    std::string path = output;
    if (path.empty()) {
      const std::string stem = cs.path.substr(cs.path.find_last_of('/') + 1);
      path = stem.substr(0, stem.rfind('.')) + "_refine.h5";
    }
    file = std::make_unique<ResultsFile>(path);
    file->attribute("rfem_version", RFEM_VERSION_STRING);
    file->attribute("case_path", cs.path);
    file->attribute("case_text", cs.text);
    file->attribute("procedure", std::string("refine"));
    install_signal_handlers();
  }
  const bool quiet = c.json || c.quiet;
  std::vector<double> val(ns.size()), change(ns.size(), NAN), order(ns.size(), NAN), extrap(ns.size(), NAN);
  for (size_t i = 0; i < ns.size(); ++i) {
    if (!quiet && dynamic) fmt::print(stderr, "[{}/{}] n = {}\n", i + 1, ns.size(), ns[i]);
    val[i] = dynamic ? evaluate_dynamic(cs, inputs, ns[i], dq, *file, true) : evaluate_quantity(cs, ns[i], quantity, o);
    if (dynamic && stop_flag().load()) return 128 + stop_flag().load();
    if (i >= 1) change[i] = val[i] - val[i - 1];
    // Observed order from three successive values: p = ln(|Δ_{i−1}| / |Δ_i|) / ln(n_i / n_{i−1}).
    if (i >= 2 && change[i] != 0.0 && change[i - 1] != 0.0) {
      order[i] = std::log(std::abs(change[i - 1] / change[i])) / std::log(double(ns[i]) / ns[i - 1]);
      const double r = std::pow(double(ns[i]) / ns[i - 1], order[i]);
      extrap[i] = val[i] + change[i] / (r - 1.0);
    }
  }
  if (file) write_table(*file, quantity, ns, val, change, order, extrap);
  if (c.json) {
    nlohmann::json rows = nlohmann::json::array();
    auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
    for (size_t i = 0; i < ns.size(); ++i)
      rows.push_back({{"n", ns[i]}, {"value", val[i]}, {"change", num(change[i])}, {"order", num(order[i])},
                      {"richardson", num(extrap[i])}});
    print_json({{"command", "refine"}, {"case", cs.path}, {"quantity", quantity}, {"rows", rows},
                {"output", file ? file->path() : ""}});
    return 0;
  }
  fmt::print("refinement of {} for {}\n{:>6} {:>20} {:>14} {:>8} {:>20}\n", cs.name.empty() ? cs.path : cs.name, quantity,
             "n", "value", "change", "order", "Richardson");
  auto opt = [](double x, const char* f) { return std::isfinite(x) ? fmt::format(fmt::runtime(f), x) : std::string("-"); };
  for (size_t i = 0; i < ns.size(); ++i)
    fmt::print("{:>6} {:>20.12e} {:>14} {:>8} {:>20}\n", ns[i], val[i], opt(change[i], "{:.3e}"), opt(order[i], "{:.3f}"),
               opt(extrap[i], "{:.12e}"));
  if (file) fmt::print("every run and the table in {}\n", file->path());
  return 0;
}

}  // namespace rfem::app
