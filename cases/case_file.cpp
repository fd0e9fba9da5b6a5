#include "cases/case_file.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/rotation.hpp"

namespace rfem {

namespace {

constexpr long kMaxRfes = 10000000;  // far beyond memory; guards int overflow of n and parts

// Reads typed values from a toml table with the file, line and dotted key in every error.
class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& what) const {
    std::ostringstream os;
    os << file_;
    if (node && node->source().begin.line > 0) os << ":" << node->source().begin.line;
    else os << " (--set or missing)";
    os << ": " << key << ": " << what;
    throw CaseError(os.str());
  }

  /// A legal but suspicious value: a one-line warning naming file, line and key.
  void warn(const toml::node* node, const std::string& key, const std::string& what) const {
    std::ostringstream os;
    os << file_;
    if (node && node->source().begin.line > 0) os << ":" << node->source().begin.line;
    os << ": " << key << ": " << what;
    warnings_.push_back(os.str());
  }
  const std::vector<std::string>& warnings() const { return warnings_; }

  /// An angle [rad]: a number (radians), or a string "90 deg" / "1.5 rad". A plain number beyond
  /// ±2π is taken as radians but warned about (TOML has no π; degrees are a common slip).
  double angle(const toml::table& t, const std::string& path, const std::string& key, double dflt) const {
    const toml::node* n = t.get(key);
    const std::string k = join(path, key);
    if (!n) return dflt;
    if (auto s = n->as_string()) {
      std::istringstream is(s->get());
      double v = 0.0;
      std::string unit;
      if (!(is >> v) || !(is >> unit) || (unit != "deg" && unit != "rad") || !std::isfinite(v))
        fail(n, k, "an angle is a number (radians) or a string \"<number> deg\" or \"<number> rad\" (got \"" + s->get() + "\")");
      return unit == "deg" ? v * M_PI / 180.0 : v;
    }
    const double v = number(t, path, key, dflt);
    if (std::abs(v) > 2 * M_PI + 1e-9)
      warn(n, k, "|" + fmt(v) + "| rad is more than a turn: if degrees were meant, write \"" + fmt(v) + " deg\"");
    return v;
  }

  void check_keys(const toml::table& t, const std::string& path, const std::set<std::string>& allowed) const {
    for (const auto& [k, v] : t)
      if (!allowed.count(std::string(k.str()))) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(&v, join(path, std::string(k.str())), "unknown key (allowed: " + list + ")");
      }
  }

  const toml::table& table(const toml::table& t, const std::string& path, const std::string& key) const {
    const toml::node* n = t.get(key);
    if (!n) fail(&t, join(path, key), "missing table");
    if (!n->is_table()) fail(n, join(path, key), "must be a table");
    return *n->as_table();
  }

  double number(const toml::table& t, const std::string& path, const std::string& key,
                std::optional<double> dflt = std::nullopt) const {
    const toml::node* n = t.get(key);
    const std::string k = join(path, key);
    if (!n) {
      if (dflt) return *dflt;
      fail(&t, k, "missing (a number is required)");
    }
    double v;
    if (auto f = n->as_floating_point()) v = f->get();
    else if (auto i = n->as_integer()) v = static_cast<double>(i->get());
    else fail(n, k, std::string("must be a number, not ") + type_name(*n));
    if (!std::isfinite(v)) fail(n, k, "must be finite (got " + std::to_string(v) + ")");
    return v;
  }

  double positive(const toml::table& t, const std::string& path, const std::string& key,
                  std::optional<double> dflt = std::nullopt) const {
    const double v = number(t, path, key, dflt);
    if (!(v > 0.0)) fail(t.get(key) ? t.get(key) : &t, join(path, key), "must be positive (got " + fmt(v) + ")");
    return v;
  }

  double non_negative(const toml::table& t, const std::string& path, const std::string& key, double dflt) const {
    const double v = number(t, path, key, dflt);
    if (v < 0.0) fail(t.get(key), join(path, key), "must not be negative (got " + fmt(v) + ")");
    return v;
  }

  long integer(const toml::table& t, const std::string& path, const std::string& key, long dflt, long min,
               long max) const {
    const toml::node* n = t.get(key);
    if (!n) return dflt;
    auto i = n->as_integer();
    if (!i) fail(n, join(path, key), std::string("must be an integer, not ") + type_name(*n));
    if (i->get() < min) fail(n, join(path, key), "must be at least " + std::to_string(min) + " (got " + std::to_string(i->get()) + ")");
    if (i->get() > max) fail(n, join(path, key), "must be at most " + std::to_string(max) + " (got " + std::to_string(i->get()) + ")");
    return static_cast<long>(i->get());
  }

  std::string string(const toml::table& t, const std::string& path, const std::string& key,
                     std::optional<std::string> dflt = std::nullopt) const {
    const toml::node* n = t.get(key);
    if (!n) {
      if (dflt) return *dflt;
      fail(&t, join(path, key), "missing (a string is required)");
    }
    auto s = n->as_string();
    if (!s) fail(n, join(path, key), std::string("must be a string, not ") + type_name(*n));
    return s->get();
  }

  Vec3 vec3(const toml::table& t, const std::string& path, const std::string& key, Vec3 dflt) const {
    const toml::node* n = t.get(key);
    if (!n) return dflt;
    auto a = n->as_array();
    if (!a || a->size() != 3) fail(n, join(path, key), "must be an array of three numbers");
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      const toml::node& e = *a->get(i);
      if (auto f = e.as_floating_point()) v[i] = f->get();
      else if (auto x = e.as_integer()) v[i] = static_cast<double>(x->get());
      else fail(&e, join(path, key), "must be an array of three numbers");
      if (!std::isfinite(v[i])) fail(&e, join(path, key), "must be finite");
    }
    return v;
  }

  static std::string join(const std::string& a, const std::string& b) { return a.empty() ? b : a + "." + b; }
  mutable std::vector<std::string> warnings_;
  static std::string fmt(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
  }
  static const char* type_name(const toml::node& n) {
    switch (n.type()) {
      case toml::node_type::table: return "a table";
      case toml::node_type::array: return "an array";
      case toml::node_type::string: return "a string";
      case toml::node_type::integer: return "an integer";
      case toml::node_type::floating_point: return "a float";
      case toml::node_type::boolean: return "a boolean";
      default: return "a date/time";
    }
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

// "a.b.0.c=value": parse the value as TOML and put it at the path (creating tables as needed).
void apply_override(toml::table& root, const std::string& file, const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw CaseError(file + ": --set " + spec + ": expected key.path=value");
  const std::string path = spec.substr(0, eq), value = spec.substr(eq + 1);
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error& e) {
    // A bare word is taken as a string (e.g. --set joints.0.type=prismatic).
    try {
      parsed = toml::parse("v = \"" + value + "\"");
    } catch (const toml::parse_error&) {
      throw CaseError(file + ": --set " + path + ": cannot parse value '" + value + "'");
    }
  }
  std::vector<std::string> keys;
  std::stringstream ss(path);
  for (std::string k; std::getline(ss, k, '.');) keys.push_back(k);
  toml::node* cur = &root;
  for (size_t i = 0; i < keys.size(); ++i) {
    const bool last = i + 1 == keys.size();
    const std::string& k = keys[i];
    if (auto t = cur->as_table()) {
      if (last) {
        t->insert_or_assign(k, *parsed.get("v"));
        return;
      }
      if (!t->get(k)) t->insert(k, toml::table{});
      cur = t->get(k);
    } else if (auto a = cur->as_array()) {
      size_t idx = 0;
      try {
        idx = std::stoul(k);
      } catch (...) {
        throw CaseError(file + ": --set " + path + ": '" + k + "' must be an array index");
      }
      if (idx >= a->size()) throw CaseError(file + ": --set " + path + ": index " + k + " out of range");
      if (last) {
        a->replace(a->begin() + static_cast<long>(idx), *parsed.get("v"));
        return;
      }
      cur = a->get(idx);
    } else {
      throw CaseError(file + ": --set " + path + ": '" + keys[i - 1] + "' is not a table or array");
    }
  }
}

Mat4 transform(const Reader& r, const toml::table& t, const std::string& path) {
  r.check_keys(t, path, {"xyz", "rpy"});
  return homogeneous(rot_rpy(r.vec3(t, path, "rpy", Vec3::Zero())), r.vec3(t, path, "xyz", Vec3::Zero()));
}

Material read_material(const Reader& r, const toml::table& t, const std::string& path, const std::string& name) {
  r.check_keys(t, path, {"E", "G", "rho"});
  Material m;
  m.name = name;
  m.E = r.positive(t, path, "E");
  m.G = r.positive(t, path, "G");
  m.rho = r.positive(t, path, "rho");
  if (m.G > m.E / 2)
    r.warn(t.get("G"), path + ".G", "G > E/2 means a negative Poisson's ratio (nu = E/2G - 1 = " + Reader::fmt(m.E / (2 * m.G) - 1) + ")");
  if (m.E < 1e5) r.warn(t.get("E"), path + ".E", "E = " + Reader::fmt(m.E) + " Pa is very small: units are SI (Pa), not GPa or MPa");
  if (m.rho < 10) r.warn(t.get("rho"), path + ".rho", "rho = " + Reader::fmt(m.rho) + " kg/m^3 is very small: units are SI (kg/m^3), not g/cm^3");
  return m;
}

Section read_section(const Reader& r, const toml::table& t, const std::string& path, const std::string& name) {
  if (t.get("box")) {
    r.check_keys(t, path, {"box", "kappa_y", "kappa_z"});
    const toml::table& b = r.table(t, path, "box");
    const std::string bp = path + ".box";
    r.check_keys(b, bp, {"outer", "inner"});
    const double outer = r.positive(b, bp, "outer"), inner = r.non_negative(b, bp, "inner", 0.0);
    if (inner >= outer) r.fail(b.get("inner"), bp + ".inner", "must be smaller than outer");
    Section s = box_section(name, outer, inner);
    s.kappa_y = r.positive(t, path, "kappa_y", s.kappa_y);
    s.kappa_z = r.positive(t, path, "kappa_z", s.kappa_z);
    return s;
  }
  r.check_keys(t, path, {"A", "Iy", "Iz", "J", "kappa_y", "kappa_z", "offset_y", "offset_z"});
  Section s;
  s.name = name;
  s.A = r.positive(t, path, "A");
  s.Iy = r.positive(t, path, "Iy");
  s.Iz = r.positive(t, path, "Iz");
  s.J = r.positive(t, path, "J");
  s.kappa_y = r.positive(t, path, "kappa_y", 5.0 / 6.0);
  s.kappa_z = r.positive(t, path, "kappa_z", 5.0 / 6.0);
  s.offset = Vec3(0.0, r.number(t, path, "offset_y", 0.0), r.number(t, path, "offset_z", 0.0));
  for (const char* k : {"Iy", "Iz"}) {
    const double I = k[1] == 'y' ? s.Iy : s.Iz;
    // A thin tube of radius ρ and wall t has I/A² = ρ/(4πt): 10 A² is a wall of ρ/125 (Kane's beam,
    // a real one, has I = 1.25 A²).
    if (I > 10 * s.A * s.A)
      r.warn(t.get(k), path + "." + k, "a second moment of 10 A^2 or more (" + Reader::fmt(I) + " m^4 against A^2 = " +
                                           Reader::fmt(s.A * s.A) + " m^4) needs an extremely thin wall: check the units (m^4, m^2)");
  }
  if (s.J > 1.0001 * (s.Iy + s.Iz))
    r.warn(t.get("J"), path + ".J", "a torsion constant larger than Iy + Iz is impossible for a real section");
  return s;
}

template <class T>
std::map<std::string, T> read_named(const Reader& r, const toml::table& root, const std::string& key,
                                    T (*read)(const Reader&, const toml::table&, const std::string&, const std::string&)) {
  std::map<std::string, T> out;
  const toml::node* n = root.get(key);
  if (!n) return out;
  if (!n->is_table()) r.fail(n, key, "must be a table of named entries");
  for (const auto& [k, v] : *n->as_table()) {
    const std::string path = key + "." + std::string(k.str());
    if (!v.is_table()) r.fail(&v, path, "must be a table");
    out.emplace(std::string(k.str()), read(r, *v.as_table(), path, std::string(k.str())));
  }
  return out;
}

// A rigid body: `extra` names keys the caller reads itself (a payload's `at`).
Mat4 read_body(const Reader& r, const toml::table& t, const std::string& path,
               const std::map<std::string, Material>& mats, const std::map<std::string, Section>& secs,
               const std::set<std::string>& extra = {}) {
  if (t.get("section")) {
    // Uniform prismatic link along its frame's x axis from the origin.
    std::set<std::string> keys{"section", "material", "length"};
    keys.insert(extra.begin(), extra.end());
    r.check_keys(t, path, keys);
    const std::string sn = r.string(t, path, "section"), mn = r.string(t, path, "material");
    if (!secs.count(sn)) r.fail(t.get("section"), path + ".section", "no section named '" + sn + "'");
    if (!mats.count(mn)) r.fail(t.get("material"), path + ".material", "no material named '" + mn + "'");
    const double L = r.positive(t, path, "length");
    const Section& s = secs.at(sn);
    const double rho = mats.at(mn).rho, mass = rho * s.A * L;
    Mat3 I = Mat3::Zero();  // about the mass centre; Ixx from the polar second moment
    I(0, 0) = rho * L * (s.Iy + s.Iz);
    I(1, 1) = mass * L * L / 12.0 + rho * L * s.Iy;
    I(2, 2) = mass * L * L / 12.0 + rho * L * s.Iz;
    return pseudo_inertia(mass, Vec3(0.5 * L, 0, 0), I);
  }
  std::set<std::string> keys{"mass", "com", "inertia"};
  keys.insert(extra.begin(), extra.end());
  r.check_keys(t, path, keys);
  const double mass = r.non_negative(t, path, "mass", 0.0);
  const Vec3 com = r.vec3(t, path, "com", Vec3::Zero());
  Mat3 I = Mat3::Zero();
  if (const toml::node* n = t.get("inertia")) {
    auto a = n->as_array();
    if (!a || a->size() != 6) r.fail(n, path + ".inertia", "must be [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]");
    double v[6];
    for (int i = 0; i < 6; ++i) {
      const toml::node& e = *a->get(i);
      if (auto f = e.as_floating_point()) v[i] = f->get();
      else if (auto x = e.as_integer()) v[i] = static_cast<double>(x->get());
      else r.fail(&e, path + ".inertia", "must be six numbers");
      if (!std::isfinite(v[i])) r.fail(&e, path + ".inertia", "must be finite");
    }
    I << v[0], v[3], v[4], v[3], v[1], v[5], v[4], v[5], v[2];
    if (I.selfadjointView<Eigen::Upper>().eigenvalues().minCoeff() < 0.0 || v[0] + v[1] < v[2] ||
        v[1] + v[2] < v[0] || v[0] + v[2] < v[1])
      r.fail(n, path + ".inertia", "is not a physical inertia tensor");
  }
  return pseudo_inertia(mass, com, I);
}

JointDrive read_drive(const Reader& r, const toml::table& t, const std::string& path) {
  r.check_keys(t, path, {"inertia", "damping", "friction", "friction_velocity"});
  JointDrive d;
  d.inertia = r.non_negative(t, path, "inertia", d.inertia);
  d.damping = r.non_negative(t, path, "damping", d.damping);
  d.friction = r.non_negative(t, path, "friction", d.friction);
  d.friction_velocity = r.positive(t, path, "friction_velocity", d.friction_velocity);
  return d;
}

InputSpec read_input(const Reader& r, const toml::table& t, const std::string& path, const std::string& case_dir) {
  InputSpec in;
  std::ostringstream where;  // (ostringstream: GCC 12 warns falsely on ":" + std::to_string)
  where << r.file();
  if (t.source().begin.line) where << ":" << t.source().begin.line;
  where << ": " << path;
  in.where = where.str();
  in.kind = r.string(t, path, "kind");
  auto file_key = [&]() {
    const std::string f = r.string(t, path, "file");
    in.file = (f.empty() || f[0] == '/') ? f : case_dir + f;
    if (!std::ifstream(in.file)) r.fail(t.get("file"), path + ".file", "cannot open '" + in.file + "'");
  };
  if (in.kind == "deployment") {
    r.check_keys(t, path, {"kind", "alpha", "T"});
    in.alpha = r.number(t, path, "alpha");
    in.T = r.positive(t, path, "T");
  } else if (in.kind == "spinup") {
    r.check_keys(t, path, {"kind", "Omega", "T"});
    in.Omega = r.number(t, path, "Omega");
    in.T = r.positive(t, path, "T");
  } else if (in.kind == "constant_rate") {
    r.check_keys(t, path, {"kind", "rate"});
    in.rate = r.number(t, path, "rate");
  } else if (in.kind == "table" || in.kind == "torque_table") {
    r.check_keys(t, path, {"kind", "file"});
    file_key();
  } else if (in.kind == "torque") {
    r.check_keys(t, path, {"kind", "value"});
    in.value = r.number(t, path, "value", 0.0);
  } else if (in.kind == "torque_from_run") {
    r.check_keys(t, path, {"kind", "file", "run", "joint"});
    file_key();
    in.run = r.string(t, path, "run");
    in.joint = static_cast<int>(r.integer(t, path, "joint", 0, 1, 1000));
  } else if (in.kind == "pd") {
    r.check_keys(t, path, {"kind", "reference", "kp", "kd", "feedforward"});
    const toml::node* rn = t.get("reference");
    if (!rn || !rn->is_table())
      r.fail(rn ? rn : &t, path + ".reference", "a PD input needs a reference motion {kind = \"deployment\", …}");
    in.reference = std::make_shared<InputSpec>(read_input(r, *rn->as_table(), path + ".reference", case_dir));
    if (!in.reference->prescribed())
      r.fail(rn, path + ".reference.kind", "the reference must be a motion (deployment, spinup, constant_rate, table)");
    in.kp = r.non_negative(t, path, "kp", 0.0);
    in.kd = r.non_negative(t, path, "kd", 0.0);
    in.feedforward = r.string(t, path, "feedforward", std::string("none"));
    if (in.feedforward != "none" && in.feedforward != "rigid")
      r.fail(t.get("feedforward"), path + ".feedforward", "must be \"none\" or \"rigid\" (got \"" + in.feedforward + "\")");
  } else {
    r.fail(t.get("kind"), path + ".kind",
           "unknown input '" + in.kind + "' (deployment, spinup, constant_rate, table, torque, torque_table, torque_from_run, pd)");
  }
  return in;
}

Simulation read_simulation(const Reader& r, const toml::table& t) {
  const std::string p = "simulation";
  r.check_keys(t, p, {"t_end", "output_dt", "rtol", "atol", "atol_velocity", "max_step", "procedure", "store_flexible_every",
                      "max_order", "max_steps", "integrator", "method", "initial"});
  Simulation s;
  IntegratorOptions& o = s.options;
  o.t_end = r.positive(t, p, "t_end");
  o.output_dt = r.positive(t, p, "output_dt", std::min(o.output_dt, o.t_end));
  if (o.output_dt > o.t_end) r.fail(t.get("output_dt"), p + ".output_dt", "must not exceed t_end");
  o.rtol = r.positive(t, p, "rtol", o.rtol);
  o.atol = r.positive(t, p, "atol", o.atol);
  o.atol_velocity = r.positive(t, p, "atol_velocity", o.atol_velocity);
  o.max_step = r.non_negative(t, p, "max_step", o.max_step);
  s.procedure = r.string(t, p, "procedure", s.procedure);
  if (s.procedure != "single" && s.procedure != "paper")
    r.fail(t.get("procedure"), p + ".procedure", "must be \"single\" or \"paper\" (got \"" + s.procedure + "\")");
  s.flexible_every = static_cast<int>(r.integer(t, p, "store_flexible_every", s.flexible_every, 0, 1000000000));
  const std::string kind = r.string(t, p, "integrator", integrator_name(o.kind));
  if (!parse_integrator(kind, o.kind))
    r.fail(t.get("integrator"), p + ".integrator", "must be \"esdirk\" or \"bdf\" (got \"" + kind + "\")");
  o.max_order = static_cast<int>(r.integer(t, p, "max_order", o.max_order, 1, 5));
  if (t.get("max_order") && o.kind != IntegratorKind::Bdf)
    r.fail(t.get("max_order"), p + ".max_order", "applies to integrator = \"bdf\" only");
  o.esdirk_table = r.string(t, p, "method", o.esdirk_table);
  if (t.get("method")) {
    if (o.kind != IntegratorKind::Esdirk) r.fail(t.get("method"), p + ".method", "applies to integrator = \"esdirk\" only");
    try {
      check_esdirk_table(o.esdirk_table);
    } catch (const std::exception& e) {
      r.fail(t.get("method"), p + ".method", e.what());
    }
  }
  o.max_steps = r.integer(t, p, "max_steps", o.max_steps, 1, 1000000000);
  const std::string initial = r.string(t, p, "initial", o.initial == InitialState::Static ? "static" : "undeformed");
  if (initial != "static" && initial != "undeformed")
    r.fail(t.get("initial"), p + ".initial", "must be \"static\" or \"undeformed\" (got \"" + initial + "\")");
  o.initial = initial == "static" ? InitialState::Static : InitialState::Undeformed;
  return s;
}

// [base] kind = "free": six joints (free_base_joints) ahead of [[joints]], torque-free, starting
// at the given pose and rates; the bus body rides on the last.
void read_base(const Reader& r, const toml::node* bn, const std::map<std::string, Material>& mats,
               const std::map<std::string, Section>& secs,
               const std::string& path, Case& c) {
  if (!bn->is_table()) r.fail(bn, "base", "must be a table {kind = \"free\", body = …}");
  const toml::table& bt = *bn->as_table();
  r.check_keys(bt, "base", {"kind", "body", "position", "velocity", "yaw", "pitch", "roll", "yaw_rate", "pitch_rate",
                            "roll_rate"});
  const std::string kind = r.string(bt, "base", "kind", std::string("fixed"));
  if (kind == "fixed") {
    // (the free base's keys stay legal, so `--set base.kind=fixed` compares the two)
    if (bt.size() > 1) r.warn(&bt, "base", "kind = \"fixed\": the first joint sits on the ground; the other keys are not used");
    return;
  }
  if (kind != "free") r.fail(bt.get("kind"), "base.kind", "must be \"fixed\" or \"free\" (got \"" + kind + "\")");
  const toml::node* body = bt.get("body");
  if (!body || !body->is_table()) r.fail(body ? body : &bt, "base.body", "a free base needs a body table {mass, com, inertia}");
  const Mat4 H = read_body(r, *body->as_table(), "base.body", mats, secs);
  if (!(H(3, 3) > 0.0)) r.fail(body, "base.body.mass", "a free base needs a positive mass");
  const Vec3 x = r.vec3(bt, "base", "position", Vec3::Zero()), xd = r.vec3(bt, "base", "velocity", Vec3::Zero());
  const double att[3] = {r.angle(bt, "base", "yaw", 0.0), r.angle(bt, "base", "pitch", 0.0), r.angle(bt, "base", "roll", 0.0)};
  const double rates[3] = {r.number(bt, "base", "yaw_rate", 0.0), r.number(bt, "base", "pitch_rate", 0.0),
                           r.number(bt, "base", "roll_rate", 0.0)};
  if (std::abs(att[1]) >= free_base_pitch_limit)
    r.fail(bt.get("pitch"), "base.pitch", "must lie within ±" + Reader::fmt(free_base_pitch_limit * 180 / M_PI) +
                                              "° (yaw–pitch–roll angles are singular at ±90°)");
  std::vector<Joint> js = free_base_joints(H);
  const long m0 = c.joint_values.size();
  VecX values(m0 + free_base_dofs), rates_all(m0 + free_base_dofs);
  values << x, att[0], att[1], att[2], c.joint_values;
  rates_all << xd, rates[0], rates[1], rates[2], c.joint_rates;
  c.joint_values = values;
  c.joint_rates = rates_all;
  std::vector<InputSpec> ins(free_base_dofs);
  std::ostringstream where;
  where << path << ":" << bt.source().begin.line << ": base";
  for (InputSpec& in : ins) in.where = where.str();
  c.inputs.insert(c.inputs.begin(), ins.begin(), ins.end());
  c.joints.insert(c.joints.begin(), js.begin(), js.end());
  c.free_base = true;
}

}  // namespace

Case read_case(const std::string& path, const std::vector<std::string>& overrides) {
  Case c;
  c.path = path;
  std::ifstream in(path);
  if (std::filesystem::is_directory(path)) throw CaseError(path + ": is a directory, not a case file (e.g. " + path + "/paper_deployment.toml)");
  if (!in) throw CaseError(path + ": cannot open case file");
  std::stringstream buf;
  buf << in.rdbuf();
  c.text = buf.str();
  toml::table root;
  try {
    root = toml::parse(c.text, path);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << path << ":" << e.source().begin.line << ": syntax error: " << e.description();
    throw CaseError(os.str());
  }
  for (const auto& o : overrides) apply_override(root, path, o);
  c.overrides = overrides;
  {
    std::ostringstream os;
    os << root;
    c.effective_text = os.str();
  }
  const Reader r(path);
  r.check_keys(root, "", {"case", "materials", "sections", "link", "joints", "gravity", "loads", "simulation", "base"});
  const auto slash = path.find_last_of('/');
  const std::string case_dir = slash == std::string::npos ? std::string() : path.substr(0, slash + 1);

  if (const toml::node* n = root.get("case")) {
    if (!n->is_table()) r.fail(n, "case", "must be a table");
    r.check_keys(*n->as_table(), "case", {"name", "description"});
    c.name = r.string(*n->as_table(), "case", "name", std::string());
    c.description = r.string(*n->as_table(), "case", "description", std::string());
  }
  const auto mats = read_named<Material>(r, root, "materials", read_material);
  const auto secs = read_named<Section>(r, root, "sections", read_section);

  if (const toml::node* ln = root.get("link")) {
    if (!ln->is_table()) r.fail(ln, "link", "must be a table");
    const toml::table& lt = *ln->as_table();
    r.check_keys(lt, "link", {"n", "damping_beta", "mount", "segments", "payloads"});
    c.has_link = true;
    c.n = static_cast<int>(r.integer(lt, "link", "n", 0, 1, kMaxRfes));
    c.link.damping_beta = r.non_negative(lt, "link", "damping_beta", 0.0);
    if (const toml::node* mn = lt.get("mount")) {
      if (!mn->is_table()) r.fail(mn, "link.mount", "must be a table {xyz, rpy}");
      c.mount = transform(r, *mn->as_table(), "link.mount");
    }
    const toml::node* sn = lt.get("segments");
    if (!sn) r.fail(&lt, "link.segments", "missing: a link needs at least one segment");
    auto arr = sn->as_array();
    if (!arr || arr->empty() || !arr->is_array_of_tables())
      r.fail(sn, "link.segments", "must be a non-empty array of tables ([[link.segments]])");
    for (size_t i = 0; i < arr->size(); ++i) {
      const toml::table& st = *arr->get(i)->as_table();
      const std::string p = "link.segments." + std::to_string(i);
      r.check_keys(st, p, {"length", "material", "section", "parts"});
      Segment s;
      s.length = r.positive(st, p, "length");
      const std::string mn = r.string(st, p, "material"), sc = r.string(st, p, "section");
      if (!mats.count(mn)) r.fail(st.get("material"), p + ".material", "no material named '" + mn + "'");
      if (!secs.count(sc)) r.fail(st.get("section"), p + ".section", "no section named '" + sc + "'");
      s.material = mats.at(mn);
      s.section = secs.at(sc);
      if (!st.get("parts") && c.n == 0) r.fail(&st, p + ".parts", "missing (give parts per segment or link.n)");
      s.parts = static_cast<int>(r.integer(st, p, "parts", 1, 1, kMaxRfes));
      c.link.segments.push_back(s);
    }
    if (const toml::node* pn = lt.get("payloads")) {
      auto pa = pn->as_array();
      if (!pa || !pa->is_array_of_tables()) r.fail(pn, "link.payloads", "must be an array of tables ([[link.payloads]])");
      const double L = c.link.total_length();
      for (size_t i = 0; i < pa->size(); ++i) {
        const toml::table& pt = *pa->get(i)->as_table();
        const std::string p = "link.payloads." + std::to_string(i);
        Payload pl;
        if (const toml::node* an = pt.get("at"); an && an->is_string() && an->as_string()->get() == "tip") pl.at = L;
        else pl.at = r.number(pt, p, "at");
        if (pl.at < 0.0 || pl.at > L * (1 + 1e-12))
          r.fail(pt.get("at"), p + ".at", "must lie on the link, 0 to " + Reader::fmt(L) + " m, or be \"tip\" (got " + Reader::fmt(pl.at) + ")");
        pl.at = std::min(pl.at, L);
        pl.H = read_body(r, pt, p, mats, secs, {"at"});
        if (pl.H(3, 3) <= 0.0) r.fail(&pt, p + ".mass", "a payload needs a positive mass");
        c.link.payloads.push_back(pl);
      }
    }
    if (c.n > 0 && c.n < static_cast<int>(c.link.segments.size()))
      r.fail(lt.get("n"), "link.n", "n = " + std::to_string(c.n) + " cannot cover " +
                                        std::to_string(c.link.segments.size()) + " segments (one part each at least)");
  }

  if (const toml::node* jn = root.get("joints")) {
    auto arr = jn->as_array();
    if (!arr || !arr->is_array_of_tables()) r.fail(jn, "joints", "must be an array of tables ([[joints]])");
    c.joint_values.resize(static_cast<long>(arr->size()));
    c.joint_rates.resize(static_cast<long>(arr->size()));
    for (size_t i = 0; i < arr->size(); ++i) {
      const toml::table& jt = *arr->get(i)->as_table();
      const std::string p = "joints." + std::to_string(i);
      r.check_keys(jt, p, {"name", "type", "alpha", "a", "theta", "d", "axis", "value", "rate", "body", "drive", "input"});
      Joint j;
      j.name = r.string(jt, p, "name", "joint" + std::to_string(i + 1));
      const std::string type = r.string(jt, p, "type", std::string("revolute"));
      if (type == "revolute") j.type = JointType::Revolute;
      else if (type == "prismatic") j.type = JointType::Prismatic;
      else r.fail(jt.get("type"), p + ".type", "must be \"revolute\" or \"prismatic\" (got \"" + type + "\")");
      j.alpha = r.angle(jt, p, "alpha", 0.0);
      j.a = r.number(jt, p, "a", 0.0);
      j.theta = r.angle(jt, p, "theta", 0.0);
      j.d = r.number(jt, p, "d", 0.0);
      j.axis = r.vec3(jt, p, "axis", Vec3::UnitZ());
      if (!(j.axis.norm() > 0.0)) r.fail(jt.get("axis"), p + ".axis", "must be a non-zero direction");
      j.axis.normalize();
      c.joint_values[static_cast<long>(i)] =
          j.type == JointType::Revolute ? r.angle(jt, p, "value", 0.0) : r.number(jt, p, "value", 0.0);
      c.joint_rates[static_cast<long>(i)] = r.number(jt, p, "rate", 0.0);
      if (const toml::node* bn = jt.get("body")) {
        if (!bn->is_table()) r.fail(bn, p + ".body", "must be a table");
        j.H = read_body(r, *bn->as_table(), p + ".body", mats, secs);
      }
      if (const toml::node* dn = jt.get("drive")) {
        if (!dn->is_table()) r.fail(dn, p + ".drive", "must be a table {inertia = …, damping = …, friction = …}");
        j.drive = read_drive(r, *dn->as_table(), p + ".drive");
      }
      InputSpec in;
      {
        std::ostringstream where;
        where << path << ":" << jt.source().begin.line << ": " << p << ".input";
        in.where = where.str();
      }
      if (const toml::node* inn = jt.get("input")) {
        if (!inn->is_table()) r.fail(inn, p + ".input", "must be a table {kind = …}");
        in = read_input(r, *inn->as_table(), p + ".input", case_dir);
      }
      c.inputs.push_back(in);
      c.joints.push_back(j);
    }
  }
  if (const toml::node* bn = root.get("base")) read_base(r, bn, mats, secs, path, c);
  if (!c.has_link && c.joints.empty()) r.fail(&root, "link", "a case needs a flexible link, joints, or both");

  if (const toml::node* gn = root.get("gravity")) {
    if (!gn->is_table()) r.fail(gn, "gravity", "must be a table");
    r.check_keys(*gn->as_table(), "gravity", {"g"});
    c.gravity = r.non_negative(*gn->as_table(), "gravity", "g", 0.0);
  }
  if (const toml::node* sn = root.get("simulation")) {
    if (!sn->is_table()) r.fail(sn, "simulation", "must be a table");
    c.sim = read_simulation(r, *sn->as_table());
    c.has_simulation = true;
    if (c.sim.procedure == "paper" && c.free_base)
      r.fail(sn->as_table()->get("procedure"), "simulation.procedure",
             "the paper procedure prescribes every joint; a free base has none to prescribe");
    if (c.sim.procedure == "paper")
      for (const InputSpec& in : c.inputs)
        if (!in.prescribed())
          throw CaseError(in.where + ": the paper procedure needs a motion law on every joint (got '" + in.kind + "')");
  }
  if (const toml::node* ln = root.get("loads")) {
    if (!ln->is_table()) r.fail(ln, "loads", "must be a table");
    r.check_keys(*ln->as_table(), "loads", {"tip_force", "tip_moment"});
    c.loads.force = r.vec3(*ln->as_table(), "loads", "tip_force", Vec3::Zero());
    c.loads.moment = r.vec3(*ln->as_table(), "loads", "tip_moment", Vec3::Zero());
  }
  c.warnings = r.warnings();
  return c;
}

Model build_model(const Case& c, int n) {
  Discretisation d;
  if (c.has_link) {
    FlexibleLink link = c.link;
    const int total = n > 0 ? n : c.n;
    if (total > 0) {
      try {
        const auto parts = distribute_parts(link, total);
        for (size_t s = 0; s < parts.size(); ++s) link.segments[s].parts = parts[s];
      } catch (const std::invalid_argument& e) {
        throw CaseError(c.path + ": link.n: " + e.what());
      }
    }
    d = discretise(link);
  }
  Model m = make_model(c.joints, c.mount, std::move(d), c.gravity);
  m.free_base = c.free_base;
  return m;
}

}  // namespace rfem
