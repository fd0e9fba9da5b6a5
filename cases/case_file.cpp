#include "case_file.hpp"
#include "../solvers/modes.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "case_reading_impl.hpp"

namespace rfem {

using namespace reading;

namespace {

// Puts `value` at keys[i…] below `cur`: tables are created as needed, "*" stands for every element
// of an array (joints.*.input.T=5).
void set_at(toml::node& cur, const std::vector<std::string>& keys, size_t i, const toml::node& value,
            const std::string& where) {
  const std::string& k = keys[i];
  const bool last = i + 1 == keys.size();
  if (auto t = cur.as_table()) {
    if (k == "*") throw CaseError(where + ": '*' stands for every element of an array, and '" + keys[i - 1] + "' is a table");
    if (last) {
      t->insert_or_assign(k, value);
      return;
    }
    if (!t->get(k)) t->insert(k, toml::table{});
    set_at(*t->get(k), keys, i + 1, value, where);
  } else if (auto a = cur.as_array()) {
    std::vector<size_t> which;
    if (k == "*") {
      if (a->empty()) throw CaseError(where + ": '" + keys[i - 1] + "' has no elements");
      for (size_t j = 0; j < a->size(); ++j) which.push_back(j);
    } else {
      size_t idx = 0, used = 0;
      try {
        idx = std::stoul(k, &used);
      } catch (...) {
        used = 0;
      }
      if (used == 0 || used != k.size())
        throw CaseError(where + ": '" + k + "' must be an array index (0, 1, …) or '*' ('" + keys[i - 1] + "' is an array)");
      if (idx >= a->size())
        throw CaseError(where + ": index " + k + " out of range ('" + keys[i - 1] + "' has " + std::to_string(a->size()) + ")");
      which.push_back(idx);
    }
    for (size_t j : which) {
      if (last) a->replace(a->begin() + static_cast<long>(j), value);
      else set_at(*a->get(j), keys, i + 1, value, where);
    }
  } else {
    throw CaseError(where + ": '" + keys[i - 1] + "' is not a table or array");
  }
}

// "a.b.0.c=value": parse the value as TOML and put it at the path. Errors name the option.
void apply_override(toml::table& root, const std::string& file, const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw CaseError(file + ": --set " + spec + ": expected key.path=value");
  const std::string path = spec.substr(0, eq), value = spec.substr(eq + 1);
  const std::string where = file + ": --set " + path;
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error& e) {
    // A bare word is taken as a string (e.g. --set joints.0.type=prismatic).
    try {
      parsed = toml::parse("v = \"" + value + "\"");
    } catch (const toml::parse_error&) {
      throw CaseError(where + ": cannot parse value '" + value + "'");
    }
  }
  std::vector<std::string> keys;
  std::stringstream ss(path);
  for (std::string k; std::getline(ss, k, '.');) keys.push_back(k);
  if (keys.empty() || std::any_of(keys.begin(), keys.end(), [](const std::string& k) { return k.empty(); }))
    throw CaseError(where + ": expected key.path=value");
  // [link] and [[links]]: say which keys this case has rather than creating the other.
  if (keys[0] == "link" && root.get("links") && !root.get("link"))
    throw CaseError(where + ": this case has several links ([[links]]): use links.0." +
                    (keys.size() > 1 ? keys[1] : std::string("…")) + ", links.*." + (keys.size() > 1 ? keys[1] : std::string("…")) +
                    (keys.size() > 1 && keys[1] == "n" ? ", or --n N for the rfes of all links" : ""));
  if (keys[0] == "links" && root.get("link") && !root.get("links"))
    throw CaseError(where + ": this case has one link ([link]): use link." + (keys.size() > 2 ? keys[2] : std::string("…")));
  set_at(root, keys, 0, *parsed.get("v"), where);
}


SimulationSettings read_simulation(const Reader& r, const toml::table& t) {
  const std::string p = "simulation";
  r.check_keys(t, p, {"t_end", "output_dt", "rtol", "atol", "atol_velocity", "max_step", "procedure", "store_flexible_every",
                      "max_order", "max_steps", "integrator", "linear_solver", "method", "initial", "state"});
  SimulationSettings s;
  IntegratorOptions& o = s.options;
  o.t_end = r.positive(t, p, "t_end");
  o.output_dt = r.positive(t, p, "output_dt", std::min(o.output_dt, o.t_end));
  if (o.output_dt > o.t_end) r.fail(t.get("output_dt"), p + ".output_dt", "must not exceed t_end");
  if (!(o.t_end / o.output_dt <= kMaxOutputs))
    r.fail(t.get("output_dt"), p + ".output_dt",
           "t_end / output_dt = " + Reader::fmt(o.t_end / o.output_dt) + " outputs is more than a results file can take (1e8)");
  o.rtol = r.positive(t, p, "rtol", o.rtol);
  o.atol = r.positive(t, p, "atol", o.atol);
  o.atol_velocity = r.positive(t, p, "atol_velocity", o.atol_velocity);
  o.max_step = r.non_negative(t, p, "max_step", o.max_step);
  const std::string procedure = r.string(t, p, "procedure", to_string(s.procedure));
  if (!parse(procedure, s.procedure))
    r.fail(t.get("procedure"), p + ".procedure", "must be \"single\" or \"paper\" (got \"" + procedure + "\")");
  s.flexible_every = static_cast<int>(r.integer(t, p, "store_flexible_every", s.flexible_every, 0, 1000000000));
  const std::string kind = r.string(t, p, "integrator", integrator_name(o.kind));
  if (!parse_integrator(kind, o.kind))
    r.fail(t.get("integrator"), p + ".integrator", "must be \"esdirk\" or \"bdf\" (got \"" + kind + "\")");
  const std::string solver = r.string(t, p, "linear_solver", linear_solver_name(o.linear_solver));
  if (!parse_linear_solver(solver, o.linear_solver))
    r.fail(t.get("linear_solver"), p + ".linear_solver", "must be \"chain\" or \"cholmod\" (got \"" + solver + "\")");
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
  s.state = r.string(t, p, "state", std::string());
  if (t.get("state") && (s.state.empty() || s.state.find('\0') != std::string::npos))
    r.fail(t.get("state"), p + ".state", "must name a state file (rfem.SimulationState.save)");
  if (!s.state.empty() && s.procedure != Procedure::Single)
    r.fail(t.get("state"), p + ".state", "a run from a saved state is one run: procedure = \"single\"");
  if (!s.state.empty() && o.kind != IntegratorKind::Esdirk)
    r.fail(t.get("state"), p + ".state", "a run from a saved state integrates with \"esdirk\"");
  try {  // what the integrator itself refuses (the one home of those rules)
    check_options(o);
  } catch (const std::invalid_argument& e) {
    r.fail(&t, p, e.what());
  }
  return s;
}

// [accuracy]: relative = 1e-3, max_n = N, max_time = S, [accuracy.absolute] "peak:u1" = 2e-4 (cases/accuracy_spec.hpp).
AccuracySpec read_accuracy(const Reader& r, const toml::node* an, const std::string& path) {
  if (!an->is_table()) r.fail(an, "accuracy", "must be a table (relative = 1e-3, max_n, [accuracy.absolute])");
  const toml::table& t = *an->as_table();
  r.check_keys(t, "accuracy", {"relative", "max_n", "max_time", "absolute"});
  AccuracySpec a;
  auto where = [&](const toml::node* n, const std::string& key) {
    return path + (n && n->source().begin.line > 0 ? ":" + std::to_string(n->source().begin.line) : std::string()) + ": " + key;
  };
  if (const toml::node* n = t.get("relative")) {
    const double v = r.number(t, "accuracy", "relative");
    check_relative_target(v, where(n, "accuracy.relative"));
    a.relative = v;
  }
  a.max_n = static_cast<int>(r.integer(t, "accuracy", "max_n", 0, 2, kMaxRfes));
  if (t.get("max_time")) a.max_time = r.positive(t, "accuracy", "max_time", 0.0);
  if (const toml::node* n = t.get("absolute")) {
    if (!n->is_table()) r.fail(n, "accuracy.absolute", "must be a table of QUANTITY = ERROR, e.g. \"peak:u1\" = 2e-4");
    for (const auto& [k, v] : *n->as_table()) {
      const std::string key = "accuracy.absolute." + std::string(k.str());
      const double e = r.number(*n->as_table(), "accuracy.absolute", std::string(k.str()));
      if (!(e > 0.0)) r.fail(&v, key, "an absolute error bar must be positive (got " + Reader::fmt(e) + ")");
      a.absolute.push_back({std::string(k.str()), e, where(&v, key)});
    }
  }
  if (!a.given()) r.fail(an, "accuracy", "gives no target: relative = 1e-3, or [accuracy.absolute] \"peak:u1\" = 2e-4");
  return a;
}

// [base] kind = "free": six joints (free_base_joints) ahead of [[joints]], torque-free, starting

}  // namespace

Case read_case(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path);
  if (std::filesystem::is_directory(path)) throw CaseError(path + ": is a directory, not a case file (e.g. " + path + "/paper_deployment.toml)");
  if (!in) throw CaseError(path + ": cannot open case file");
  std::stringstream buf;
  buf << in.rdbuf();
  const auto slash = path.find_last_of('/');
  return parse_case(buf.str(), path, overrides, slash == std::string::npos ? std::string() : path.substr(0, slash + 1));
}

Case with_overrides(const Case& c, const std::vector<std::string>& more) {
  std::vector<std::string> all = c.overrides;
  all.insert(all.end(), more.begin(), more.end());
  return parse_case(c.text, c.path, all, c.base_dir);
}

Case parse_case(const std::string& text, const std::string& path, const std::vector<std::string>& overrides,
                const std::string& base_dir) {
  Case c;
  c.path = path;
  c.base_dir = base_dir.empty() || base_dir.back() == '/' ? base_dir : base_dir + "/";
  c.text = text;
  toml::table root = parse_toml(c.text, path);
  for (const auto& o : overrides) apply_override(root, path, o);
  c.overrides = overrides;
  {
    std::ostringstream os;
    os << root;
    c.effective_text = os.str();
  }
  Reader r(path);
  r.check_keys(root, "", {"case", "materials", "sections", "link", "links", "joints", "gravity", "loads", "simulation", "base", "sensors", "accuracy"});
  const std::string& case_dir = c.base_dir;

  if (const toml::node* n = root.get("case")) {
    if (!n->is_table()) r.fail(n, "case", "must be a table");
    const toml::table& ct = *n->as_table();
    r.check_keys(ct, "case", {"name", "description", "accept"});
    c.name = r.string(ct, "case", "name", std::string());
    c.description = r.string(ct, "case", "description", std::string());
    if (const toml::node* an = ct.get("accept")) {  // warnings the case knows of and keeps
      const toml::array* a = an->as_array();
      if (!a) r.fail(an, "case.accept", "must be an array of keys whose warnings the case acknowledges, e.g. [\"sections.B2.J\"]");
      for (const toml::node& k : *a) {
        if (!k.is_string()) r.fail(&k, "case.accept", "must be an array of keys (strings)");
        r.accept(k.as_string()->get());
      }
    }
  }
  const Materials mats = read_materials(r, root);
  const Sections secs = read_sections(r, root);
  std::vector<ParentRef> joint_parents, link_parents;
  read_links(r, root, mats, secs, c, link_parents);
  if (const toml::node *jn = root.get("joints"), *bn = root.get("base");
      jn && !jn->is_array() && bn && bn->is_table() && bn->as_table()->get("urdf"))
    refuse_joints_table(r, *jn, *bn->as_table(), case_dir);  // a URDF joint's setting meant
  read_joints(r, root, mats, secs, case_dir, c, joint_parents);
  if (const toml::node* bn = root.get("base")) read_base(r, bn, mats, secs, path, case_dir, c, joint_parents);
  resolve_parents(r, c, joint_parents, link_parents);
  c.sensors = read_sensors(r, root, c);
  if (!c.has_link() && c.joints.empty()) r.fail(&root, "link", "a case needs a flexible link, joints, or both");

  if (const toml::node* gn = root.get("gravity")) {
    if (!gn->is_table()) r.fail(gn, "gravity", "must be a table");
    r.check_keys(*gn->as_table(), "gravity", {"g"});
    c.gravity = r.non_negative(*gn->as_table(), "gravity", "g", 0.0);
  }
  if (const toml::node* sn = root.get("simulation")) {
    if (!sn->is_table()) r.fail(sn, "simulation", "must be a table");
    c.sim = read_simulation(r, *sn->as_table());
    c.has_simulation = true;
    if (!c.sim.state.empty() && c.sim.state[0] != '/' && !case_dir.empty()) c.sim.state = case_dir + "/" + c.sim.state;
    if (c.sim.procedure == Procedure::Paper && c.free_base)
      r.fail(sn->as_table()->get("procedure"), "simulation.procedure",
             "the paper procedure prescribes every joint; a free base has none to prescribe");
    if (c.sim.procedure == Procedure::Paper)
      for (const InputSpec& in : c.inputs)
        if (!in.prescribed())
          throw CaseError(in.where + ": the paper procedure needs a motion law on every joint (got '" + to_string(in.kind) + "')");
  }
  if (const toml::node* ln = root.get("loads")) {
    if (!ln->is_table()) r.fail(ln, "loads", "must be a table");
    const toml::table& lt = *ln->as_table();
    r.check_keys(lt, "loads", {"tip_force", "tip_moment", "link"});
    c.loads.force = r.vec3(lt, "loads", "tip_force", Vec3::Zero());
    c.loads.moment = r.vec3(lt, "loads", "tip_moment", Vec3::Zero());
    if (lt.get("link")) {
      const std::string name = r.string(lt, "loads", "link");
      c.loads.link = c.link_index(name);
      if (c.loads.link < 0) r.fail(lt.get("link"), "loads.link", "no link named '" + name + "'");
    }
  }
  if (const toml::node* an = root.get("accuracy")) c.accuracy = read_accuracy(r, an, path);
  for (const std::string& k : r.unused_accepts())
    r.warn(root.get("case"), "case.accept", "'" + k + "' draws no warning here: nothing to acknowledge");
  c.warnings = r.warnings();
  return c;
}

std::vector<std::vector<int>> link_parts(const Case& c, int n) {
  // (The caller's n: "--n" on the command line, `n` in Python and the library.)
  if (n < 0 || n > kMaxRfes)
    throw CaseError(c.path + ": --n " + std::to_string(n) + ": must be 1 to " + std::to_string(kMaxRfes) + " rfes");
  size_t segments = 0;
  for (const LinkCase& l : c.links) segments += l.link.segments.size();
  if (n > 0 && segments == 0)
    throw CaseError(c.path + ": --n " + std::to_string(n) +
                    ": the case has no flexible link ([link] or [[links]]) to divide into rfes; a rigid manipulator takes no n");
  std::vector<std::vector<int>> parts;
  for (const LinkCase& l : c.links) {
    parts.emplace_back();
    for (const Segment& s : l.link.segments) parts.back().push_back(s.parts);
  }
  try {
    if (n > 0) {  // n in all: every link's segments apportioned together by length
      FlexibleLink all;
      for (const LinkCase& l : c.links) all.segments.insert(all.segments.end(), l.link.segments.begin(), l.link.segments.end());
      const std::vector<int> p = distribute_parts(all, n);
      size_t s = 0;
      for (auto& lp : parts)
        for (int& x : lp) x = p[s++];
    } else {
      for (size_t l = 0; l < c.links.size(); ++l)
        if (c.links[l].n > 0) parts[l] = distribute_parts(c.links[l].link, c.links[l].n);
    }
  } catch (const std::invalid_argument& e) {
    throw CaseError(c.path + ": " + (c.links.size() == 1 ? c.links[0].key + ".n" : std::string("--n")) + ": " + e.what());
  }
  return parts;
}

Model build_model(const Case& c, int n) {
  const auto parts = link_parts(c, n);
  std::vector<MountedLink> links;
  for (size_t l = 0; l < c.links.size(); ++l) {
    FlexibleLink link = c.links[l].link;
    for (size_t s = 0; s < parts[l].size(); ++s) link.segments[s].parts = parts[l][s];
    MountedLink ml;
    ml.name = c.links[l].name;
    try {
      ml.d = discretise(link);
    } catch (const std::invalid_argument& e) {
      throw CaseError(c.path + ": " + c.links[l].key + ": " + e.what());
    }
    ml.on = c.links[l].on;
    ml.d.modes = c.links[l].modes;
    if (ml.d.modes > kModalAxes * ml.d.n())
      throw CaseError(c.path + (c.links[l].modes_line > 0 ? ":" + std::to_string(c.links[l].modes_line) : std::string(" (--set or missing)")) + ": " +
                      c.links[l].key + ".modes: " + std::to_string(ml.d.modes) + " modes, but n = " + std::to_string(ml.d.n()) +
                      " rfes have only " + std::to_string(kModalAxes * ml.d.n()) + " to keep (3 per rfe, the rotations: the displacements stay unknowns)");
    ml.d.derivatives = c.links[l].derivatives;
    if (ml.d.derivatives > ml.d.modes)
      throw CaseError(c.path + (c.links[l].derivatives_line > 0 ? ":" + std::to_string(c.links[l].derivatives_line) : std::string(" (--set or missing)")) +
                      ": " + c.links[l].key + ".derivatives: " + std::to_string(ml.d.derivatives) +
                      " is more than the modes kept (" + std::to_string(ml.d.modes) + "): derivatives are of kept modes");
    links.push_back(std::move(ml));
  }
  try {
    return make_model(c.joints, std::move(links), c.gravity, c.free_base);
  } catch (const std::invalid_argument& e) {
    throw CaseError(c.path + ": " + e.what());
  }
}

}  // namespace rfem
