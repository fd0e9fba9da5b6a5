// `rfem refine`: quantities over a series of n. Every quantity is checked before the first run;
// dynamic quantities share one simulation per n; the finest n is run again at tighter tolerances
// to estimate the integration error; solvers/refinement.hpp says what the series can be trusted
// for. Ctrl-C keeps (and prints) the rows done so far.
#include <fmt/core.h>

#include <cctype>
#include <cmath>
#include <memory>

#include "apps/simulate.hpp"
#include "solvers/modes.hpp"
#include "solvers/refinement.hpp"
#include "solvers/statics.hpp"

namespace rfem::app {

namespace {

// "A/B/Q": the prefixes A, B and the quantity Q. A prefix that names a link of the case sets
// `link`; any other is the run (`run`, empty if none). Throws for more prefixes than that.
std::string split_prefixes(const Case& cs, const std::string& quantity, std::string& run, int& link) {
  std::string q = quantity;
  run.clear();
  link = -1;
  for (auto slash = q.find('/'); slash != std::string::npos; slash = q.find('/')) {
    const std::string p = q.substr(0, slash);
    q = q.substr(slash + 1);
    const int l = cs.link_index(p);
    if (l >= 0 && link < 0) link = l;
    else if (l < 0 && run.empty() && link < 0) run = p;
    else throw CaseError("--quantity " + quantity + ": expected [RUN/][LINK/]QUANTITY ('" + p + "' is not where a run or link goes)");
  }
  return q;
}

// A static or modal quantity: "[LINK/]tip:ux|uy|uz|rx|ry|rz" (the last link by default),
// "mode:K", "axial:K", "bending-y:K", "bending-z:K", "torsion:K".
struct StaticQuantity {
  std::string what;
  int index = 0;  // tip component 0..5, or mode K ≥ 1
  int link = -1;  // tip: the link (−1: the last)
};

StaticQuantity parse_static(const Case& cs, const std::string& text) {
  StaticQuantity s;
  std::string run;
  const std::string quantity = split_prefixes(cs, text, run, s.link);
  if (!run.empty()) throw CaseError("--quantity " + text + ": no link named '" + run + "'");
  if (s.link >= 0 && quantity.rfind("tip:", 0) != 0) throw CaseError("--quantity " + text + ": only tip quantities name a link");
  const auto colon = quantity.find(':');
  s.what = quantity.substr(0, colon);
  const std::string arg = colon == std::string::npos ? "" : quantity.substr(colon + 1);
  if (s.what == "tip") {
    static const char* names[6] = {"ux", "uy", "uz", "rx", "ry", "rz"};
    for (int i = 0; i < 6; ++i)
      if (arg == names[i]) {
        s.index = i;
        return s;
      }
    throw CaseError("--quantity " + quantity + ": tip component must be ux, uy, uz, rx, ry or rz");
  }
  if (s.what != "mode" && s.what != "axial" && s.what != "bending-y" && s.what != "bending-z" && s.what != "torsion")
    throw CaseError("--quantity " + quantity + ": unknown quantity '" + s.what +
                    "' ([LINK/]tip:ux…rz, mode:K, axial:K, bending-y:K, bending-z:K, torsion:K, "
                    "[RUN/][LINK/]peak:u1|u2|theta, [RUN/][LINK/]u1@T, u2@T, theta@T, [RUN/]tauJ@T, qJ@T)");
  size_t used = 0;
  try {
    s.index = std::stoi(arg, &used);
  } catch (...) {
    used = 0;
  }
  if (used == 0 || used != arg.size() || s.index < 1)
    throw CaseError("--quantity " + quantity + ": expected " + s.what + ":K with an integer K ≥ 1");
  return s;
}

double evaluate_static(const Case& cs, int n, const StaticQuantity& s, const std::string& quantity, const ModesOptions& o) {
  const Model model = build_model(cs, n);
  VecX qb, vb;
  joint_state(cs, o, qb, vb);
  if (s.what == "tip") {
    if (model.links.empty()) throw CaseError("--quantity " + quantity + ": the case has no flexible link");
    const int l = s.link >= 0 ? s.link : static_cast<int>(model.links.size()) - 1;
    return tip_motion(model, l, solve_static(model, qb, vb, cs.loads).q)[s.index];
  }
  const int k = s.index;
  if (s.what == "mode") {
    if (k > model.flexible_dofs())
      throw CaseError("--quantity " + quantity + ": n = " + std::to_string(n) + " has only " + std::to_string(model.flexible_dofs()) + " modes");
    return compute_modes(model, qb, vb, k).omega[k - 1] / (2 * M_PI);
  }
  // Modes of one kind can sit high in the spectrum (axial modes of a slender beam): widen the
  // search until the k-th one appears.
  for (int count = std::min(model.flexible_dofs(), 4 * k + 8);; count = std::min(model.flexible_dofs(), 2 * count)) {
    const ModesResult r = compute_modes(model, qb, vb, count);
    int seen = 0;
    for (int i = 0; i < count; ++i)
      if (to_string(r.kind[i]) == s.what && ++seen == k) return r.omega[i] / (2 * M_PI);
    if (count == model.flexible_dofs()) break;
  }
  throw std::runtime_error("--quantity " + quantity + ": no such mode among all " + std::to_string(model.flexible_dofs()) +
                           " at n = " + std::to_string(n));
}

// A dynamic quantity "[RUN/][LINK/]peak:u1|u2|theta", "[RUN/][LINK/]u1@T", "u2@T", "theta@T",
// "[RUN/]tauJ@T", "qJ@T" (J 1-based; the last link by default).
struct DynamicQuantity {
  std::string run, what;
  double time = -1.0;  // < 0: peak over the run
  int joint = -1;
  int link = -1;
};

// Returns false if `quantity` is not dynamic; throws CaseError if it is but cannot be evaluated.
bool parse_dynamic(const Case& cs, const std::string& quantity, DynamicQuantity& d) {
  const bool paper = cs.sim.procedure == "paper";
  const bool prefixed = quantity.find('/') != std::string::npos;
  const std::string q = split_prefixes(cs, quantity, d.run, d.link);
  if (d.run.empty()) d.run = paper ? "kinematic" : "run";
  if (q.rfind("peak:", 0) == 0) {
    d.what = q.substr(5);
  } else if (const auto at = q.find('@'); at != std::string::npos) {
    d.what = q.substr(0, at);
    size_t used = 0;
    try {
      d.time = std::stod(q.substr(at + 1), &used);
    } catch (...) {
      used = 0;
    }
    if (used == 0 || used != q.size() - at - 1 || !std::isfinite(d.time))
      throw CaseError("--quantity " + quantity + ": '" + q.substr(at + 1) + "' is not a time");
  } else {
    if (prefixed && q.rfind("tip:", 0) != 0) throw CaseError("--quantity " + quantity + ": expected RUN/peak:X or RUN/X@T");
    return false;
  }
  if (d.what.rfind("tau", 0) == 0 || (d.what.size() > 1 && d.what[0] == 'q' && std::isdigit(d.what[1]))) {
    const std::string num = d.what.substr(d.what[0] == 'q' ? 1 : 3);
    d.joint = num.empty() ? 0 : std::atoi(num.c_str());
    if (d.joint < 1 || d.joint > static_cast<int>(cs.joints.size()))
      throw CaseError("--quantity " + quantity + ": joint must be 1.." + std::to_string(cs.joints.size()));
    d.what = d.what[0] == 'q' ? "q" : "tau";
    if (d.link >= 0) throw CaseError("--quantity " + quantity + ": joint quantities name no link");
  } else if (d.what != "u1" && d.what != "u2" && d.what != "theta") {
    throw CaseError("--quantity " + quantity + ": expected u1, u2, theta, tauJ or qJ");
  } else if (cs.links.empty()) {
    throw CaseError("--quantity " + quantity + ": the case has no flexible link");
  }
  if (!cs.has_simulation) throw CaseError(cs.path + ": simulation: a dynamic quantity needs a [simulation] table");
  const bool known = paper ? (d.run == "rigid" || d.run == "kinematic" || d.run == "force") : d.run == "run";
  if (!known)
    throw CaseError("--quantity " + quantity + ": no run or link named '" + d.run + "' (" +
                    (paper ? "the paper procedure runs rigid, kinematic and force" : "a single run is named run") +
                    (cs.links.empty() ? std::string() : "; links: " + [&] {
                      std::string l;
                      for (const LinkCase& lc : cs.links) l += (l.empty() ? "" : ", ") + lc.name;
                      return l;
                    }()) + ")");
  const IntegratorOptions& o = cs.sim.options;
  if (d.time >= 0) {
    const double k = std::round(d.time / o.output_dt);
    const bool on_grid = std::abs(d.time - k * o.output_dt) <= 1e-9 * std::max(1.0, d.time) || d.time == o.t_end;
    if (d.time > o.t_end * (1 + 1e-12) || !on_grid)
      throw CaseError("--quantity " + quantity + ": t = " + fmt::format("{}", d.time) + " s is not an output time (0 … " +
                      fmt::format("{}", o.t_end) + " s every " + fmt::format("{}", o.output_dt) + " s)");
  }
  return true;
}

struct Quantity {
  std::string text;
  bool dynamic = false;
  StaticQuantity s;
  DynamicQuantity d;
};

// One simulation at n: every dynamic quantity observed in it.
std::vector<double> evaluate_dynamic(const Case& cs, const std::vector<JointInput>& inputs, int n,
                                     const std::vector<Quantity>& qs, ResultsFile* file, const std::string& prefix,
                                     int threads) {
  // (file is never null: refine opens one whenever a quantity is dynamic)
  const Model model = build_model(cs, n);
  std::vector<double> value(qs.size(), NAN), best_dt(qs.size(), 1e300);
  for (size_t i = 0; i < qs.size(); ++i)
    if (qs[i].dynamic && qs[i].d.time < 0) value[i] = 0.0;
  auto observe = [&](const std::string& run, const Model& m, const OutputSample& s) {
    for (size_t i = 0; i < qs.size(); ++i) {
      const DynamicQuantity& d = qs[i].d;
      if (!qs[i].dynamic || run != prefix + d.run) continue;
      double x = 0.0;
      if (d.what == "tau") x = s.tau[d.joint - 1];
      else if (d.what == "q") x = s.q[m.joint_index(d.joint - 1)];
      else x = tip_deflection(m, d.link >= 0 ? d.link : static_cast<int>(m.links.size()) - 1, s.q)[d.what == "u1" ? 0 : d.what == "u2" ? 1 : 2];
      if (d.time < 0) value[i] = std::max(value[i], std::abs(x));
      else if (std::abs(s.t - d.time) < best_dt[i]) best_dt[i] = std::abs(s.t - d.time), value[i] = x;
    }
  };
  const auto runs = simulate_case(cs, model, inputs, *file, prefix, true, observe, threads);
  for (const auto& r : runs)
    if (!r.completed) {
      if (stop_flag().load()) return {};
      throw std::runtime_error("n = " + std::to_string(n) + ": " + r.name + " " + r.status);
    }
  return value;
}

void put(hid_t g, const char* name, const std::vector<double>& v) {
  const hsize_t dims[1] = {v.size()};
  const hid_t sp = H5Screate_simple(1, dims, nullptr);
  const hid_t ds = H5Dcreate2(g, name, H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (!v.empty()) H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Dclose(ds);
  H5Sclose(sp);
}

// Group `refine`: n and, per quantity, refine/q<k> with value, change, order, richardson and its
// assessment; the first quantity's datasets also directly in `refine`.
void write_table(ResultsFile& file, const std::vector<Quantity>& qs, const std::vector<int>& ns,
                 const std::vector<Refinement>& tables, const std::string& status) {
  if (H5Lexists(file.id(), "refine", H5P_DEFAULT) > 0) H5Ldelete(file.id(), "refine", H5P_DEFAULT);
  const hid_t g = H5Gcreate2(file.id(), "refine", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  put(g, "n", std::vector<double>(ns.begin(), ns.end()));
  write_attribute(g, "status", status);
  write_attribute(g, "quantities", static_cast<double>(qs.size()));
  for (size_t k = 0; k < qs.size(); ++k) {
    const Refinement& t = tables[k];
    std::vector<double> val, change, order, rich;
    for (const auto& r : t.rows) {
      val.push_back(r.value);
      change.push_back(r.change);
      order.push_back(r.order);
      rich.push_back(r.richardson);
    }
    const hid_t q = H5Gcreate2(g, ("q" + std::to_string(k)).c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    for (hid_t where : {q, k == 0 ? g : hid_t(-1)}) {
      if (where < 0) continue;
      put(where, "value", val);
      put(where, "change", change);
      put(where, "order", order);
      put(where, "richardson", rich);
      write_attribute(where, "quantity", qs[k].text);
      write_attribute(where, "fitted_order", t.fitted_order);
      write_attribute(where, "integration_error", t.integration_error);
      std::string w;
      for (const auto& x : t.warnings) w += (w.empty() ? "" : "\n") + x;
      write_attribute(where, "warnings", w);
      if (std::isfinite(t.reference())) write_attribute(where, "reference", t.reference());
    }
    H5Gclose(q);
  }
  H5Gclose(g);
  file.flush();
}

void print_tables(const Case& cs, const std::vector<Quantity>& qs, const std::vector<Refinement>& tables) {
  auto opt = [](double x, const char* f) { return std::isfinite(x) ? fmt::format(fmt::runtime(f), x) : std::string("-"); };
  for (size_t k = 0; k < qs.size(); ++k) {
    const Refinement& t = tables[k];
    fmt::print("refinement of {} for {}\n{:>6} {:>20} {:>14} {:>8} {:>20}\n", cs.name.empty() ? cs.path : cs.name, qs[k].text,
               "n", "value", "change", "order", "Richardson");
    for (const auto& r : t.rows)
      fmt::print("{:>6} {:>20.12e} {:>14} {:>8} {:>20}\n", r.n, r.value, opt(r.change, "{:.3e}"), opt(r.order, "{:.3f}"),
                 opt(r.richardson, "{:.12e}"));
    fmt::print("fitted order (least squares over all changes): {}", opt(t.fitted_order, "{:.3f}"));
    if (std::isfinite(t.integration_error)) fmt::print("; integration error at n = {}: {:.3e}", t.rows.back().n, t.integration_error);
    fmt::print("\n");
  }
}

}  // namespace

double evaluate_quantity(const Case& cs, int n, const std::string& quantity, const ModesOptions& o) {
  return evaluate_static(cs, n, parse_static(cs, quantity), quantity, o);
}

int run_refine(const Common& c, const RefineOptions& ro, const ModesOptions& o) {
  const Case cs = read_checked_case(c);
  if (ro.quantities.empty()) throw CaseError("--quantity: give at least one quantity (see rfem refine --help)");
  if (ro.ns.size() < 2) throw CaseError("--n: refine needs at least two values");
  for (size_t i = 1; i < ro.ns.size(); ++i)
    if (ro.ns[i] <= ro.ns[i - 1])
      throw CaseError("--n: the values must increase (" + std::to_string(ro.ns[i - 1]) + " then " + std::to_string(ro.ns[i]) + ")");
  // Every quantity and every n are checked before the first run.
  std::vector<Quantity> qs;
  bool dynamic = false;
  for (const auto& text : ro.quantities) {
    Quantity q;
    q.text = text;
    q.dynamic = parse_dynamic(cs, text, q.d);
    if (!q.dynamic) q.s = parse_static(cs, text);
    dynamic |= q.dynamic;
    qs.push_back(q);
  }
  for (int n : ro.ns) build_model(cs, n);  // an impossible discretisation fails here
  std::unique_ptr<ResultsFile> file;
  const std::vector<JointInput> inputs = dynamic ? joint_inputs(cs) : std::vector<JointInput>{};
  if (dynamic || !ro.output.empty()) {
    std::string path = ro.output;
    if (path.empty()) {
      const std::string stem = cs.path.substr(cs.path.find_last_of('/') + 1);
      path = stem.substr(0, stem.rfind('.')) + "_refine.h5";
    }
    file = std::make_unique<ResultsFile>(path);
    describe_run(*file, cs, c, "refine");
  }
  if (dynamic) check_affordable(cs, build_model(cs, ro.ns.back()), inputs, c.threads, c.json || c.quiet);
  install_signal_handlers();
  const bool quiet = c.json || c.quiet;
  std::vector<int> done;
  std::vector<std::vector<double>> values(qs.size());
  std::string status = "completed";
  for (size_t i = 0; i < ro.ns.size(); ++i) {
    const int n = ro.ns[i];
    if (!quiet) fmt::print(stderr, "[{}/{}] n = {}\n", i + 1, ro.ns.size(), n);
    std::vector<double> dyn;
    if (dynamic) dyn = evaluate_dynamic(cs, inputs, n, qs, file.get(), fmt::format("n{}/", n), c.threads);
    if (stop_flag().load()) {
      status = fmt::format("interrupted (signal {})", stop_flag().load());
      break;
    }
    for (size_t k = 0; k < qs.size(); ++k)
      values[k].push_back(qs[k].dynamic ? dyn[k] : evaluate_static(cs, n, qs[k].s, qs[k].text, o));
    done.push_back(n);
  }
  // The integration error of the finest run: the same n at tolerances 100 times tighter.
  std::vector<double> integration(qs.size(), NAN);
  if (dynamic && ro.integration_check && status == "completed") {
    if (!quiet) fmt::print(stderr, "[check] n = {} at rtol {:g}\n", done.back(), cs.sim.options.rtol / 100);
    Case tight = cs;
    tight.sim.options.rtol /= 100;
    tight.sim.options.atol /= 100;
    tight.sim.options.max_steps *= 100;
    const auto ref = evaluate_dynamic(tight, inputs, done.back(), qs, file.get(), fmt::format("check_n{}/", done.back()), c.threads);
    if (stop_flag().load()) status = fmt::format("interrupted (signal {})", stop_flag().load());
    else
      for (size_t k = 0; k < qs.size(); ++k)
        if (qs[k].dynamic) integration[k] = std::abs(values[k].back() - ref[k]);
  }
  std::vector<Refinement> tables;
  for (size_t k = 0; k < qs.size(); ++k) tables.push_back(assess_refinement(done, values[k], integration[k]));
  if (file) write_table(*file, qs, done, tables, status);
  for (size_t k = 0; k < qs.size(); ++k)  // warnings always reach stderr, with --json and --quiet too
    for (const auto& w : tables[k].warnings) fmt::print(stderr, "rfem: warning: {}: {}\n", qs[k].text, w);
  const int code = stop_flag().load() ? 128 + stop_flag().load() : 0;
  if (c.json) {
    auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
    nlohmann::json jq = nlohmann::json::array();
    for (size_t k = 0; k < qs.size(); ++k) {
      nlohmann::json rows = nlohmann::json::array();
      for (const auto& r : tables[k].rows)
        rows.push_back({{"n", r.n}, {"value", r.value}, {"change", num(r.change)}, {"order", num(r.order)},
                        {"richardson", num(r.richardson)}});
      jq.push_back({{"quantity", qs[k].text}, {"rows", rows}, {"fitted_order", num(tables[k].fitted_order)},
                    {"integration_error", num(tables[k].integration_error)}, {"warnings", tables[k].warnings}});
    }
    print_json({{"command", "refine"}, {"case", cs.path}, {"status", status}, {"quantities", jq},
                {"output", file ? file->path() : ""}});
    return code;
  }
  print_tables(cs, qs, tables);
  if (file) fmt::print("every run and the table in {}{}\n", file->path(), status == "completed" ? "" : " (" + status + ")");
  return code;
}

}  // namespace rfem::app
