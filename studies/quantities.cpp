#include "quantities.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>

#include "../core/positions.hpp"
#include "../simulation/state.hpp"
#include "../solvers/modes.hpp"
#include "../solvers/statics.hpp"
#include "linearize.hpp"
#include "modes_study.hpp"

namespace rfem {

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

void parse_static(const Case& cs, const std::string& text, Quantity& s) {
  std::string run;
  const std::string quantity = split_prefixes(cs, text, run, s.link);
  if (!run.empty()) throw CaseError("--quantity " + text + ": no link named '" + run + "'");
  if (s.link >= 0 && quantity.rfind("tip:", 0) != 0) throw CaseError("--quantity " + text + ": only tip quantities name a link");
  const auto colon = quantity.find(':');
  const std::string what = quantity.substr(0, colon);
  const std::string arg = colon == std::string::npos ? "" : quantity.substr(colon + 1);
  if (what == "tip") {
    static const char* names[6] = {"ux", "uy", "uz", "rx", "ry", "rz"};
    for (int i = 0; i < 6; ++i)
      if (arg == names[i]) {
        s.kind = Quantity::Kind::Tip;
        s.component = i;
        return;
      }
    throw CaseError("--quantity " + quantity + ": tip component must be ux, uy, uz, rx, ry or rz");
  }
  if (what != "mode" && what != "axial" && what != "bending-y" && what != "bending-z" && what != "torsion" && what != "linear")
    throw CaseError("--quantity " + quantity + ": unknown quantity '" + what +
                    "' ([LINK/]tip:ux…rz, mode:K, axial:K, bending-y:K, bending-z:K, torsion:K, linear:K; dynamic: "
                    "peak|max|min|rms|mean:SERIES[t1:t2] or SERIES@T, SERIES = [RUN/][LINK/]u1|u2|theta|tauJ|qJ|vJ|aJ "
                    "or the difference of two)");
  size_t used = 0;
  try {
    s.mode = std::stoi(arg, &used);
  } catch (...) {
    used = 0;
  }
  if (used == 0 || used != arg.size() || s.mode < 1)
    throw CaseError("--quantity " + quantity + ": expected " + what + ":K with an integer K ≥ 1");
  s.kind = what == "mode" ? Quantity::Kind::Mode : what == "linear" ? Quantity::Kind::LinearMode : Quantity::Kind::ModeOfKind;
  s.mode_kind = what;
}

// One series of a dynamic quantity: [RUN/][LINK/]NAME. Returns "" or why it is not one.
std::string parse_term(const Case& cs, const std::string& text, QuantityTerm& t) {
  const bool paper = cs.sim.procedure == Procedure::Paper;
  std::string name;
  try {
    name = split_prefixes(cs, text, t.run, t.link);
  } catch (const CaseError& e) {
    return e.what();
  }
  if (t.run.empty()) t.run = paper ? "kinematic" : "run";
  const bool joint_name = name.size() > 1 && (name.rfind("tau", 0) == 0 || ((name[0] == 'q' || name[0] == 'v' || name[0] == 'a') &&
                                                                        std::isdigit(static_cast<unsigned char>(name[1]))));
  if (joint_name) {
    const std::string num = name.substr(name[0] == 't' ? 3 : 1);
    size_t used = 0;
    try {
      t.joint = std::stoi(num, &used);
    } catch (...) {
      used = 0;
    }
    if (used == 0 || used != num.size() || t.joint < 1 || t.joint > static_cast<int>(cs.joints.size()))
      return "joint must be 1.." + std::to_string(cs.joints.size());
    t.joint_value = name[0];
    if (t.link >= 0) return "joint quantities name no link";
  } else if (name == "u1" || name == "u2" || name == "theta") {
    if (cs.links.empty()) return "the case has no flexible link";
    t.component = name == "u1" ? 0 : name == "u2" ? 1 : 2;
  } else {
    return "expected u1, u2, theta, tauJ, qJ, vJ or aJ (got '" + name + "')";
  }
  const bool known = paper ? (t.run == "rigid" || t.run == "kinematic" || t.run == "force") : t.run == "run";
  if (!known) {
    std::string links;
    for (const LinkCase& lc : cs.links) links += (links.empty() ? "" : ", ") + lc.name;
    return "no run or link named '" + t.run + "' (" +
           (paper ? "the paper procedure runs rigid, kinematic and force" : "a single run is named run") +
           (cs.links.empty() ? std::string() : "; links: " + links) + ")";
  }
  return "";
}

double number_in(const std::string& quantity, const std::string& text, const char* what) {
  size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(text, &used);
  } catch (...) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v))
    throw CaseError("--quantity " + quantity + ": '" + text + "' is not " + what);
  return v;
}

// Returns false if `quantity` is not dynamic; throws CaseError if it is but cannot be evaluated.
bool parse_dynamic(const Case& cs, const std::string& quantity, Quantity& d) {
  static const std::pair<const char*, Quantity::Aggregate> aggregates[] = {
      {"peak", Quantity::Aggregate::Peak}, {"max", Quantity::Aggregate::Max}, {"min", Quantity::Aggregate::Min},
      {"rms", Quantity::Aggregate::Rms}, {"mean", Quantity::Aggregate::Mean}};
  std::string series;
  const auto colon = quantity.find(':');
  bool aggregate = false;
  if (colon != std::string::npos) {  // AGG:SERIES, or the older PREFIX/AGG:NAME
    const std::string head = quantity.substr(0, colon);
    const auto slash = head.rfind('/');
    const std::string word = slash == std::string::npos ? head : head.substr(slash + 1);
    for (const auto& [w, a] : aggregates)
      if (word == w) {
        aggregate = true;
        d.aggregate = a;
      }
    if (aggregate) series = (slash == std::string::npos ? std::string() : head.substr(0, slash + 1)) + quantity.substr(colon + 1);
  }
  if (!cs.has_simulation && (aggregate || quantity.find('@') != std::string::npos))
    throw CaseError(cs.path + ": simulation: a dynamic quantity needs a [simulation] table");
  const IntegratorOptions& o = cs.sim.options;
  if (aggregate) {
    d.kind = Quantity::Kind::Aggregate;
    d.t1 = 0.0;
    d.t2 = o.t_end;
    if (!series.empty() && series.back() == ']') {  // a window [t1:t2]
      const auto lb = series.rfind('['), sep = series.find(':', lb == std::string::npos ? 0 : lb);
      if (lb == std::string::npos || sep == std::string::npos)
        throw CaseError("--quantity " + quantity + ": a window is [t1:t2] (seconds)");
      d.t1 = number_in(quantity, series.substr(lb + 1, sep - lb - 1), "a time");
      d.t2 = number_in(quantity, series.substr(sep + 1, series.size() - sep - 2), "a time");
      series.resize(lb);
      if (!(d.t1 >= 0.0 && d.t1 < d.t2 && d.t2 <= o.t_end * (1 + 1e-12)))
        throw CaseError("--quantity " + quantity + ": the window must lie in the run, 0 ≤ t1 < t2 ≤ " + fmt::format("{}", o.t_end) + " s");
      if (std::floor(d.t2 / o.output_dt + 1e-9) - std::ceil(d.t1 / o.output_dt - 1e-9) < 1)
        throw CaseError("--quantity " + quantity + ": the window holds fewer than two outputs (every " +
                        fmt::format("{}", o.output_dt) + " s)");
    }
  } else if (const auto at = quantity.rfind('@'); at != std::string::npos) {
    d.kind = Quantity::Kind::AtTime;
    d.time = number_in(quantity, quantity.substr(at + 1), "a time");
    series = quantity.substr(0, at);
    const double k = std::round(d.time / o.output_dt);
    const bool on_grid = std::abs(d.time - k * o.output_dt) <= 1e-9 * std::max(1.0, d.time) || d.time == o.t_end;
    if (d.time < 0 || d.time > o.t_end * (1 + 1e-12) || !on_grid)
      throw CaseError("--quantity " + quantity + ": t = " + fmt::format("{}", d.time) + " s is not an output time (0 … " +
                      fmt::format("{}", o.t_end) + " s every " + fmt::format("{}", o.output_dt) + " s)");
  } else {
    if (quantity.find('/') != std::string::npos && quantity.find("tip:") == std::string::npos)
      throw CaseError("--quantity " + quantity + ": expected AGG:[RUN/]NAME (peak:force/u1) or [RUN/]NAME@T");
    return false;
  }
  // SERIES = TERM or TERM-TERM: the first '-' that leaves two terms (names may hold '-').
  QuantityTerm a, b;
  const std::string one = parse_term(cs, series, a);
  if (one.empty()) {
    d.terms = {a};
    return true;
  }
  for (size_t dash = series.find('-'); dash != std::string::npos; dash = series.find('-', dash + 1))
    if (parse_term(cs, series.substr(0, dash), a).empty() && parse_term(cs, series.substr(dash + 1), b).empty()) {
      d.terms = {a, b};
      return true;
    }
  throw CaseError("--quantity " + quantity + ": " + one);
}

}  // namespace

Quantity parse_quantity(const Case& cs, const std::string& text) {
  Quantity q;
  q.text = text;
  if (!parse_dynamic(cs, text, q)) {
    q = Quantity{};
    q.text = text;
    parse_static(cs, text, q);
  }
  return q;
}

double evaluate_quantity(const Case& cs, int n, const Quantity& s, const JointRate& rate, const std::vector<std::string>& free) {
  if (s.dynamic()) throw std::invalid_argument("evaluate_quantity: " + s.text + " needs a run (a refinement study)");
  const Model model = build_model(cs, n);
  VecX qb, vb;
  joint_state(cs, rate, qb, vb);
  if (s.kind == Quantity::Kind::Tip) {
    if (model.links.empty()) throw CaseError("--quantity " + s.text + ": the case has no flexible link");
    const int l = s.link >= 0 ? s.link : static_cast<int>(model.links.size()) - 1;
    return tip_motion(model, l, solve_static(model, qb, vb, cs.loads).q)[s.component];
  }
  const int k = s.mode;
  if (s.kind == Quantity::Kind::LinearMode) {
    LinearizeRequest rq;
    rq.n = n;
    const auto modes = linear_modes(linearize(cs, rq), k);
    if (static_cast<int>(modes.size()) < k)
      throw CaseError("--quantity " + s.text + ": the linear model at n = " + std::to_string(n) + " has " +
                      std::to_string(modes.size()) + " oscillating modes");
    return modes[static_cast<size_t>(k - 1)].first;
  }
  const std::vector<int> freed = free_joints(cs, model, free);
  const int all = model.flexible_dofs() + static_cast<int>(freed.size());
  if (s.kind == Quantity::Kind::Mode) {
    if (k > all) throw CaseError("--quantity " + s.text + ": n = " + std::to_string(n) + " has only " + std::to_string(all) + " modes");
    return compute_modes(model, qb, vb, k, kDenseModesLimit, freed).omega[k - 1] / (2 * M_PI);
  }
  // Modes of one kind can sit high in the spectrum (axial modes of a slender beam): widen the
  // search until the k-th one appears.
  for (int count = std::min(all, 4 * k + 8);; count = std::min(all, 2 * count)) {
    const ModesResult r = compute_modes(model, qb, vb, count, kDenseModesLimit, freed);
    int seen = 0;
    for (int i = 0; i < count; ++i)
      if (to_string(r.kind[i]) == s.mode_kind && ++seen == k) return r.omega[i] / (2 * M_PI);
    if (count == all) break;
  }
  throw std::runtime_error("--quantity " + s.text + ": no such mode among all " + std::to_string(all) +
                           " at n = " + std::to_string(n));
}

double evaluate_quantity(const Case& cs, int n, const std::string& text, const JointRate& rate) {
  return evaluate_quantity(cs, n, parse_quantity(cs, text), rate);
}

double term_value(const Model& m, const QuantityTerm& t, const OutputSample& s) {
  if (t.joint > 0) {
    const int i = m.joint_index(t.joint - 1);
    switch (t.joint_value) {
      case 'q': return s.q[i];
      case 'v': return s.v[i];
      case 'a': return s.a[i];
      default: return s.tau[t.joint - 1];
    }
  }
  return tip_deflection(m, t.link >= 0 ? t.link : static_cast<int>(m.links.size()) - 1, s.q)[t.component];
}

double dynamic_value(const Quantity& q, const std::vector<double>& t, const std::vector<std::vector<double>>& series) {
  if (series.size() != q.terms.size()) throw std::invalid_argument("dynamic_value: one series per term is required");
  auto x = [&](size_t i) { return series[0][i] - (series.size() > 1 ? series[1][i] : 0.0); };
  const size_t n = t.size();
  for (const auto& s : series)
    if (s.size() != n) throw std::invalid_argument("dynamic_value: the series and the times differ in length");
  if (n == 0) return NAN;
  if (q.kind == Quantity::Kind::AtTime) {
    size_t best = 0;
    for (size_t i = 1; i < n; ++i)
      if (std::abs(t[i] - q.time) < std::abs(t[best] - q.time)) best = i;
    return x(best);
  }
  double peak = 0.0, hi = -INFINITY, lo = INFINITY, integral = 0.0, square = 0.0, span = 0.0;
  long prev = -1;
  for (size_t i = 0; i < n; ++i) {
    if (t[i] < q.t1 - 1e-9 * std::max(1.0, q.t1) || t[i] > q.t2 + 1e-9 * std::max(1.0, q.t2)) continue;
    const double v = x(i);
    peak = std::max(peak, std::abs(v));
    hi = std::max(hi, v);
    lo = std::min(lo, v);
    if (prev >= 0) {  // trapezoidal time average over the outputs in the window
      const double dt = t[i] - t[prev], u = x(prev);
      integral += 0.5 * (u + v) * dt;
      square += 0.5 * (u * u + v * v) * dt;
      span += dt;
    }
    prev = static_cast<long>(i);
  }
  switch (q.aggregate) {
    case Quantity::Aggregate::Peak: return peak;
    case Quantity::Aggregate::Max: return hi;
    case Quantity::Aggregate::Min: return lo;
    case Quantity::Aggregate::Mean: return span > 0 ? integral / span : NAN;
    case Quantity::Aggregate::Rms: return span > 0 ? std::sqrt(square / span) : NAN;
  }
  return NAN;
}

std::vector<std::string> runs_read(const std::vector<Quantity>& qs) {
  std::vector<std::string> runs;
  for (const Quantity& q : qs)
    for (const QuantityTerm& t : q.terms)
      if (std::find(runs.begin(), runs.end(), t.run) == runs.end()) runs.push_back(t.run);
  return runs;
}

QuantityRecorder::QuantityRecorder(const std::vector<Quantity>& qs, std::string prefix) : qs_(qs), prefix_(std::move(prefix)) {
  for (const Quantity& q : qs_)
    for (const QuantityTerm& t : q.terms)
      if (std::find(terms_.begin(), terms_.end(), t) == terms_.end()) terms_.push_back(t);
  series_.resize(terms_.size());
}

void QuantityRecorder::begin(const RunInfo& info) {
  model_ = info.model;
  run_ = info.name.substr(std::min(prefix_.size(), info.name.size()));
}

void QuantityRecorder::sample(const OutputSample& s) {
  bool any = false;
  for (size_t i = 0; i < terms_.size(); ++i)
    if (terms_[i].run == run_) {
      series_[i].push_back(term_value(*model_, terms_[i], s));
      any = true;
    }
  if (any) times_[run_].push_back(s.t);
}

std::vector<double> QuantityRecorder::values() const {
  std::vector<double> out(qs_.size(), NAN);
  for (size_t k = 0; k < qs_.size(); ++k) {
    const Quantity& q = qs_[k];
    if (!q.dynamic()) continue;
    std::vector<std::vector<double>> s;
    for (const QuantityTerm& t : q.terms) s.push_back(series_[std::find(terms_.begin(), terms_.end(), t) - terms_.begin()]);
    const auto times = times_.find(q.terms[0].run);
    if (times == times_.end()) continue;
    out[k] = dynamic_value(q, times->second, s);
  }
  return out;
}

std::vector<double> QuantityRecorder::save() const {
  std::vector<double> x = {static_cast<double>(series_.size())};
  for (const auto& v : series_) put_block(x, v);
  x.push_back(static_cast<double>(times_.size()));
  for (const auto& [run, t] : times_) {
    RunName r = RunName::Run;
    parse(run, r);
    x.push_back(static_cast<double>(static_cast<int>(r)));
    put_block(x, t);
  }
  return x;
}

void QuantityRecorder::restore(const std::vector<double>& x) {
  size_t i = 0;
  const std::string why = "the checkpoint's quantity series are not of these quantities";
  auto bad = [&] { return std::invalid_argument(why); };
  auto block = [&] { return take_block(x, i, why); };
  if (x.empty() || x[0] != static_cast<double>(series_.size())) throw bad();
  i = 1;
  for (auto& v : series_) v = block();
  if (i >= x.size()) throw bad();
  const double runs = x[i++];
  times_.clear();
  for (double k = 0; k < runs; ++k) {
    if (i >= x.size()) throw bad();
    const double r = x[i++];
    if (!(r >= 0 && r <= static_cast<int>(RunName::Force))) throw bad();
    const std::string run = to_string(static_cast<RunName>(static_cast<int>(r)));
    times_[run] = block();
  }
}

}  // namespace rfem
