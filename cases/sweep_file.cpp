#include "sweep_file.hpp"

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "case_reading_impl.hpp"

namespace rfem {

namespace {

namespace fs = std::filesystem;
using reading::Reader;

// A parameter's values as TOML text (an integral number as an integer: `n`, counts) and numbers.
struct Values {
  std::vector<std::string> text;
  std::vector<double> number;
};

std::string number_text(double v) {
  if (std::abs(v) < 1e15 && v == std::round(v)) return fmt::format("{}", static_cast<long long>(v));
  return fmt::format("{:.17g}", v);
}

Values read_values(const Reader& r, const toml::node& n, const std::string& key) {
  Values out;
  const std::string p = "parameters." + key;
  if (const toml::table* t = n.as_table()) {  // { from, to, count }: evenly spaced, both ends included
    r.check_keys(*t, p, {"from", "to", "count"});
    const double a = r.number(*t, p, "from"), b = r.number(*t, p, "to");
    const long count = r.integer(*t, p, "count", 2, 2, 1000000);
    for (long i = 0; i < count; ++i) {
      const double v = i + 1 == count ? b : a + (b - a) * static_cast<double>(i) / static_cast<double>(count - 1);
      out.text.push_back(number_text(v));
      out.number.push_back(v);
    }
    return out;
  }
  const toml::array* a = n.as_array();
  if (!a || a->empty()) r.fail(&n, p, "must be a non-empty array of values or a range {from, to, count}");
  for (const toml::node& v : *a) {
    if (v.is_table() || v.is_array()) r.fail(&v, p, "each value must be a number, string or boolean");
    if (auto d = v.value<double>(); d && (v.is_floating_point() || v.is_integer())) {
      if (!std::isfinite(*d)) r.fail(&v, p, "values must be finite");
      out.text.push_back(v.is_integer() ? fmt::format("{}", v.as_integer()->get()) : fmt::format("{:.17g}", *d));
      out.number.push_back(*d);
    } else if (v.is_boolean()) {
      out.text.push_back(v.as_boolean()->get() ? "true" : "false");
      out.number.push_back(v.as_boolean()->get() ? 1.0 : 0.0);
    } else {
      std::ostringstream os;
      os << *v.as_string();  // quoted and escaped, as TOML
      out.text.push_back(os.str());
      out.number.push_back(NAN);
    }
  }
  return out;
}

}  // namespace

std::string joined(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

int sweep_point_n(const Sweep& s, int k) {
  const SweepPoint& p = s.points.at(static_cast<size_t>(k));
  for (size_t i = 0; i < s.parameters.size(); ++i)
    if (s.parameters[i] == "n") return static_cast<int>(p.values[i]);
  return 0;
}

std::vector<std::string> sweep_case_overrides(const Sweep& s, int k) {
  std::vector<std::string> o = s.set;
  for (const std::string& x : s.points.at(static_cast<size_t>(k)).overrides)
    if (x.rfind("n=", 0) != 0) o.push_back(x);
  return o;
}

std::string sweep_point_name(const Sweep& s, int k) {
  return fmt::format("point {} ({})", k, joined(s.points.at(static_cast<size_t>(k)).overrides, ", "));
}

Sweep read_sweep_file(const std::string& path, const std::string& index, double checkpoint) {
  Sweep s;
  s.path = path;
  {
    std::ifstream in(path);
    if (fs::is_directory(path) || !in) throw CaseError(path + ": cannot open sweep file");
    std::stringstream b;
    b << in.rdbuf();
    s.text = b.str();
  }
  toml::table root = reading::parse_toml(s.text, path);
  const Reader r(path);
  r.check_keys(root, "", {"sweep", "parameters"});
  const toml::table& st = r.table(root, "", "sweep");
  r.check_keys(st, "sweep", {"case", "set", "quantities", "combine", "output", "checkpoint"});
  const std::string dir = fs::path(path).parent_path().string();
  const std::string given = r.string(st, "sweep", "case");
  s.case_path = given.empty() || given[0] == '/' || dir.empty() ? given : dir + "/" + given;
  auto strings = [&](const char* key) {
    std::vector<std::string> out;
    if (const toml::node* n = st.get(key)) {
      const toml::array* a = n->as_array();
      if (!a) r.fail(n, std::string("sweep.") + key, "must be an array of strings");
      for (const toml::node& v : *a) {
        if (!v.is_string()) r.fail(&v, std::string("sweep.") + key, "must be an array of strings");
        out.push_back(v.as_string()->get());
      }
    }
    return out;
  };
  s.set = strings("set");
  s.quantities = strings("quantities");
  // The index is the quantities' table: a sweep without one has nothing to record.
  if (s.quantities.empty())
    r.fail(st.get("quantities") ? st.get("quantities") : &st, "sweep.quantities",
           std::string(st.get("quantities") ? "is empty" : "missing") + ": name at least one quantity to record, e.g. quantities = [\"peak:u1\"]");
  const std::string combine = r.string(st, "sweep", "combine", std::string("grid"));
  if (combine != "grid" && combine != "zip") r.fail(st.get("combine"), "sweep.combine", "must be \"grid\" or \"zip\" (got \"" + combine + "\")");
  s.zip = combine == "zip";
  s.checkpoint = r.number(st, "sweep", "checkpoint", checkpoint);
  if (!(s.checkpoint >= 0.0))
    r.fail(st.get("checkpoint"), "sweep.checkpoint", "must be 0 (none) or a positive number of seconds (got " + std::to_string(s.checkpoint) + ")");
  s.index = !index.empty() ? index : r.string(st, "sweep", "output", fs::path(path).stem().string() + ".h5");
  if (fs::path(s.index).extension() != ".h5") r.fail(st.get("output") ? st.get("output") : &st, "sweep.output", "the index must be an .h5 file (got '" + s.index + "')");
  s.directory = (fs::path(s.index).parent_path() / (fs::path(s.index).stem().string() + ".runs")).string();

  const toml::table& pt = r.table(root, "", "parameters");
  if (pt.empty()) r.fail(&pt, "parameters", "give at least one parameter, e.g. n = [24, 48, 96]");
  std::vector<Values> values;
  for (const auto& [k, v] : pt) {
    const std::string key(k.str());
    s.parameters.push_back(key);
    values.push_back(read_values(r, v, key));
    if (key == "n")
      for (double x : values.back().number)
        if (!(x >= 1 && x == std::round(x) && x <= reading::kMaxRfes)) r.fail(&v, "parameters.n", "must be whole numbers of rfes, 1 to " + std::to_string(reading::kMaxRfes));
  }
  // The points: every combination (the last parameter fastest), or the i-th value of each.
  size_t count = 1;
  if (s.zip) {
    count = values[0].text.size();
    for (size_t i = 1; i < values.size(); ++i)
      if (values[i].text.size() != count)
        r.fail(pt.get(s.parameters[i]), "parameters." + s.parameters[i],
               fmt::format("has {} values and '{}' {}: zipped parameters need as many each", values[i].text.size(), s.parameters[0], count));
  } else {
    for (const Values& v : values) count *= v.text.size();
  }
  if (count > 1000000) r.fail(&pt, "parameters", fmt::format("{} points are more than a sweep takes (1e6)", count));
  const int width = std::max(4, static_cast<int>(std::to_string(count - 1).size()));
  for (size_t k = 0; k < count; ++k) {
    SweepPoint p;
    size_t rest = k;
    for (size_t i = values.size(); i-- > 0;) {
      const size_t j = s.zip ? k : rest % values[i].text.size();
      if (!s.zip) rest /= values[i].text.size();
      p.overrides.insert(p.overrides.begin(), s.parameters[i] + "=" + values[i].text[j]);
      p.values.insert(p.values.begin(), values[i].number[j]);
    }
    p.file = (fs::path(s.directory) / fmt::format("run{:0{}}.h5", k, width)).string();
    s.points.push_back(p);
  }
  return s;
}

}  // namespace rfem
