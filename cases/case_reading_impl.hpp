#pragma once
// The case reader's private parts (cases/case_file.hpp is the interface): typed reading of TOML
// values with file, line and key in every message, and the readers of each part of a case.
#include <toml++/toml.h>

#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "case_file.hpp"

namespace rfem::reading {

using rfem::kMaxRfes;  // (case_file.hpp)

/// TOML text parsed, or CaseError "path:line: syntax error: …".
inline toml::table parse_toml(const std::string& text, const std::string& path) {
  try {
    return toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    std::ostringstream os;
    os << path << ":" << e.source().begin.line << ": syntax error: " << e.description();
    throw CaseError(os.str());
  }
}

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

  /// A legal but suspicious value: a one-line warning naming file, line and key (unless the case
  /// acknowledges that key's warning: [case] accept).
  void warn(const toml::node* node, const std::string& key, const std::string& what) const {
    if (accepted_.count(key)) {
      used_.insert(key);
      return;
    }
    std::ostringstream os;
    os << file_;
    if (node && node->source().begin.line > 0) os << ":" << node->source().begin.line;
    os << ": " << key << ": " << what;
    warnings_.push_back(os.str());
  }
  /// A value far outside what it can physically be (a unit slip, most often): refused naming file,
  /// line and key, unless the case acknowledges that key ([case] accept), which then keeps it silently.
  void doubt(const toml::node* node, const std::string& key, const std::string& what) const {
    if (accepted_.count(key)) {
      used_.insert(key);
      return;
    }
    fail(node, key, what + "; if it is meant, acknowledge it: [case] accept = [\"" + key + "\"]");
  }
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Keys whose warnings the case acknowledges ([case] accept = ["sections.B2.J"]).
  void accept(const std::string& key) { accepted_.insert(key); }
  /// Acknowledged keys that drew no warning.
  std::vector<std::string> unused_accepts() const {
    std::vector<std::string> out;
    for (const auto& k : accepted_)
      if (!used_.count(k)) out.push_back(k);
    return out;
  }

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

  /// A positive value within [lo, hi]: the range in which rfem's derived quantities (masses,
  /// stiffnesses, frequencies) neither overflow nor vanish, far beyond any real structure.
  double ranged(const toml::table& t, const std::string& path, const std::string& key, double lo, double hi,
                const std::string& unit, std::optional<double> dflt = std::nullopt) const {
    const double v = positive(t, path, key, dflt);
    if (v < lo || v > hi)
      fail(t.get(key) ? t.get(key) : &t, join(path, key),
           "must lie within what rfem computes with, " + fmt(lo) + " to " + fmt(hi) + " " + unit + " (got " + fmt(v) + ")");
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
  std::set<std::string> accepted_;
  mutable std::set<std::string> used_;
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


/// What real materials span, defined once for the plausibility checks of [materials]: from the
/// softest solid a link is made of, a soft elastomer (E ~ 1e5 Pa, G ~ E/3 at nu = 0.5), to diamond
/// (E 1.2e12 Pa, G 5e11 Pa); from the lightest structural foams (10 kg/m^3) to osmium (2.26e4
/// kg/m^3). Beyond them a value is a unit slip (GPa or MPa for Pa, g/cm^3 for kg/m^3) far more
/// often than a material: refused unless the case acknowledges it (Reader::doubt).
struct MaterialRange {
  double lo, hi;
  bool holds(double v) const { return v >= lo && v <= hi; }
};
inline constexpr MaterialRange kPlausibleE{1e5, 1.2e12}, kPlausibleG{3e4, 6e11}, kPlausibleRho{10.0, 2.3e4};

using Materials = std::map<std::string, Material>;
using Sections = std::map<std::string, Section>;

/// A constant transform {xyz, rpy} (translation, then roll–pitch–yaw angles).
Mat4 transform(const Reader& r, const toml::table& t, const std::string& path);
/// The `mount` key of a joint or link (identity if absent).
Mat4 read_mount(const Reader& r, const toml::table& t, const std::string& path);
/// The named tables [materials.*] and [sections.*].
Materials read_materials(const Reader& r, const toml::table& root);
Sections read_sections(const Reader& r, const toml::table& root);
/// A rigid body {mass, com, inertia} or {section, material, length}; `extra` names keys the caller
/// reads itself (a payload's `at`).
Mat4 read_body(const Reader& r, const toml::table& t, const std::string& path, const Materials& mats,
               const Sections& secs, const std::set<std::string>& extra = {});
JointDrive read_drive(const Reader& r, const toml::table& t, const std::string& path);
InputSpec read_input(const Reader& r, const toml::table& t, const std::string& path, const std::string& case_dir);

/// What a joint or a link names as its parent, kept until every name is known.
struct ParentRef {
  std::string name;                  ///< "" : the default
  const toml::node* node = nullptr;  ///< the `parent` value (or the element's table) for messages
  std::string path;                  ///< "joints.2" / "links.0"
  const toml::node* at = nullptr;    ///< the `at` value, if given
  Mat4 X = Mat4::Identity();         ///< `mount`
};

/// [[joints]] into c.joints, c.inputs, c.joint_values/rates; their parents into `parents`.
void read_joints(const Reader& r, const toml::table& root, const Materials& mats, const Sections& secs,
                 const std::string& case_dir, Case& c, std::vector<ParentRef>& parents);
/// [base] urdf = "…": the URDF's movable joints ahead of the case's, its links in c.frames.
void read_urdf_base(const Reader& r, const toml::table& bt, const std::string& case_dir, Case& c,
                    std::vector<ParentRef>& parents);
/// `joints` given as a table in a case with a URDF base (`--set joints.1.input.kp=…`): refused,
/// pointing to base.joints.NAME.
[[noreturn]] void refuse_joints_table(const Reader& r, const toml::node& jn, const toml::table& bt, const std::string& case_dir);
/// A joint's input table (joints.i.input, base.joints.NAME.input).
InputSpec read_input(const Reader& r, const toml::table& t, const std::string& path, const std::string& case_dir);
/// [base] kind = "free": six joints ahead of the case's (with parents that need no names).
void read_base(const Reader& r, const toml::node* bn, const Materials& mats, const Sections& secs,
               const std::string& path, const std::string& case_dir, Case& c, std::vector<ParentRef>& parents);
/// [[sensors]], checked against c's joints and links (after resolve_parents).
std::vector<SensorSpec> read_sensors(const Reader& r, const toml::table& root, const Case& c);
/// [link] (one link) or [[links]] into c.links; their parents into `parents`.
void read_links(const Reader& r, const toml::table& root, const Materials& mats, const Sections& secs, Case& c,
                std::vector<ParentRef>& parents);
/// Resolves every parent name into the Mountings of c.joints and c.links, checks names are unique,
/// points lie on their links and the mountings form no cycle.
void resolve_parents(const Reader& r, Case& c, const std::vector<ParentRef>& joint_parents,
                       const std::vector<ParentRef>& link_parents);

}  // namespace rfem::reading
