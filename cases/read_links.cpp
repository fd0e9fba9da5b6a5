// Flexible links of a case file ([link] or [[links]]) and what every joint and link is mounted on.
#include <algorithm>
#include <cmath>

#include "case_reading_impl.hpp"
#include "../solvers/modes.hpp"

namespace rfem::reading {

namespace {

LinkCase read_link(const Reader& r, const toml::table& lt, const std::string& key, const std::string& name,
                   const Materials& mats, const Sections& secs, ParentRef& parent) {
  r.check_keys(lt, key, {"name", "parent", "at", "n", "modes", "derivatives", "damping_beta", "mount", "segments", "payloads"});
  LinkCase c;
  c.key = key;
  c.name = r.string(lt, key, "name", name);
  if (const std::string why = name_problem(c.name); !why.empty()) r.fail(lt.get("name"), key + ".name", why);
  c.n = static_cast<int>(r.integer(lt, key, "n", 0, 1, kMaxRfes));
  c.link.damping_beta = r.non_negative(lt, key, "damping_beta", 0.0);
  c.modes = static_cast<int>(r.integer(lt, key, "modes", 0, 0, 6 * kMaxRfes));
  c.modes_line = lt.get("modes") ? static_cast<int>(lt.get("modes")->source().begin.line) : 0;
  c.derivatives = static_cast<int>(r.integer(lt, key, "derivatives", 0, 0, kMaxDerivativeModes));
  c.derivatives_line = lt.get("derivatives") ? static_cast<int>(lt.get("derivatives")->source().begin.line) : 0;
  parent.path = key;
  parent.node = lt.get("parent") ? lt.get("parent") : &lt;
  parent.name = r.string(lt, key, "parent", std::string());
  parent.at = lt.get("at");
  parent.X = read_mount(r, lt, key);
  const toml::node* sn = lt.get("segments");
  if (!sn) r.fail(&lt, key + ".segments", "missing: a link needs at least one segment");
  auto arr = sn->as_array();
  if (!arr || arr->empty() || !arr->is_array_of_tables())
    r.fail(sn, key + ".segments", "must be a non-empty array of tables ([[" + key.substr(0, key.find('.')) + ".segments]])");
  for (size_t i = 0; i < arr->size(); ++i) {
    const toml::table& st = *arr->get(i)->as_table();
    const std::string p = key + ".segments." + std::to_string(i);
    r.check_keys(st, p, {"length", "material", "section", "parts"});
    Segment s;
    s.length = r.ranged(st, p, "length", 1e-6, 1e6, "m");
    const std::string mn = r.string(st, p, "material"), sc = r.string(st, p, "section");
    if (!mats.count(mn)) r.fail(st.get("material"), p + ".material", "no material named '" + mn + "'");
    if (!secs.count(sc)) r.fail(st.get("section"), p + ".section", "no section named '" + sc + "'");
    s.material = mats.at(mn);
    s.section = secs.at(sc);
    if (!st.get("parts") && c.n == 0) r.fail(&st, p + ".parts", "missing (give parts per segment or " + key + ".n)");
    s.parts = static_cast<int>(r.integer(st, p, "parts", 1, 1, kMaxRfes));
    c.link.segments.push_back(s);
  }
  if (const toml::node* pn = lt.get("payloads")) {
    auto pa = pn->as_array();
    if (!pa || !pa->is_array_of_tables()) r.fail(pn, key + ".payloads", "must be an array of tables ([[" + key + ".payloads]])");
    const double L = c.link.total_length();
    for (size_t i = 0; i < pa->size(); ++i) {
      const toml::table& pt = *pa->get(i)->as_table();
      const std::string p = key + ".payloads." + std::to_string(i);
      Payload pl;
      if (const toml::node* an = pt.get("at"); an && an->is_string() && an->as_string()->get() == "tip") pl.at = L;
      else pl.at = r.number(pt, p, "at");
      if (pl.at < 0.0 || pl.at > L * (1 + 1e-12))
        r.fail(pt.get("at"), p + ".at", "must lie on the link, 0 to " + Reader::fmt(L) + " m, or be \"tip\" (got " + Reader::fmt(pl.at) + ")");
      pl.at = std::min(pl.at, L);
      pl.H = read_body(r, pt, p, mats, secs, {"at"});
      if (pl.H(3, 3) <= 0.0) r.fail(&pt, p + ".mass", "a payload needs a positive mass");
      // A payload far heavier than its link was likely given in grams; but where a density is
      // itself implausible (accepted), the link's mass says nothing about the payload's unit.
      double link_mass = 0.0;
      bool plausible = true;
      for (const Segment& s : c.link.segments) {
        link_mass += s.material.rho * s.section.A * s.length;
        plausible = plausible && kPlausibleRho.holds(s.material.rho);
      }
      if (plausible && pl.H(3, 3) > 100 * link_mass)
        r.warn(pt.get("mass") ? pt.get("mass") : &pt, p + ".mass",
               "a payload of " + Reader::fmt(pl.H(3, 3)) + " kg is " + Reader::fmt(std::round(pl.H(3, 3) / link_mass)) +
                   " times the link's mass (" + Reader::fmt(link_mass) + " kg): units are kg (if grams were meant, write " +
                   Reader::fmt(pl.H(3, 3) * 1e-3) + ")");
      c.link.payloads.push_back(pl);
    }
  }
  if (c.n > 0 && c.n < static_cast<int>(c.link.segments.size()))
    r.fail(lt.get("n"), key + ".n", "n = " + std::to_string(c.n) + " cannot cover " +
                                        std::to_string(c.link.segments.size()) + " segments (one part each at least)");
  return c;
}

// A joint's or link's parent as an entity: a joint, a link, or the ground (kind Ground).
struct Entity {
  Mounting::Kind kind = Mounting::Kind::Ground;
  int index = -1;
};

}  // namespace

void read_links(const Reader& r, const toml::table& root, const Materials& mats, const Sections& secs, Case& c,
                std::vector<ParentRef>& parents) {
  const toml::node* one = root.get("link");
  const toml::node* many = root.get("links");
  if (one && many) r.fail(many, "links", "give one flexible link as [link] or several as [[links]], not both");
  if (one) {
    if (!one->is_table()) r.fail(one, "link", "must be a table");
    parents.emplace_back();
    c.links.push_back(read_link(r, *one->as_table(), "link", "link", mats, secs, parents.back()));
  }
  if (many) {
    auto arr = many->as_array();
    if (!arr || arr->empty() || !arr->is_array_of_tables()) r.fail(many, "links", "must be a non-empty array of tables ([[links]])");
    for (size_t i = 0; i < arr->size(); ++i) {
      parents.emplace_back();
      c.links.push_back(read_link(r, *arr->get(i)->as_table(), "links." + std::to_string(i),
                                  "link" + std::to_string(i + 1), mats, secs, parents.back()));
    }
  }
}

void resolve_parents(const Reader& r, Case& c, const std::vector<ParentRef>& joint_parents,
                       const std::vector<ParentRef>& link_parents) {
  const int m = static_cast<int>(c.joints.size()), nl = static_cast<int>(c.links.size());
  // Names: unique among joints and links, and not "ground".
  std::map<std::string, Entity> named;
  auto add = [&](const std::string& name, const Entity& e, const ParentRef& pr) {
    const std::string key = pr.path == "base" ? "base" : pr.path + ".name";
    if (name == "ground") r.fail(pr.node, key, "'ground' is reserved for the inertial frame");
    if (auto it = named.find(name); it != named.end())
      r.fail(pr.node, key, "'" + name + "' names " + (it->second.kind == Mounting::Kind::Joint ? "a joint" : "a link") +
                               " already (names must be unique among joints and links)");
    named[name] = e;
  };
  for (int j = 0; j < m; ++j) add(c.joints[j].name, {Mounting::Kind::Joint, j}, joint_parents[j]);
  for (int l = 0; l < nl; ++l) add(c.links[l].name, {Mounting::Kind::Link, l}, link_parents[l]);
  // What `self` may sit on, by kind: "joints a, b; links c; URDF links d, e; or \"ground\"".
  auto choices = [&](const Entity& self) {
    std::string js, ls, us;
    for (const auto& [k, e] : named)
      if (!(e.kind == self.kind && e.index == self.index)) (e.kind == Mounting::Kind::Joint ? js : ls) += (", " + k);
    for (const BodyFrame& b : c.frames) us += ", " + b.name;
    std::string out;
    for (const auto& [what, list] : {std::pair{"joints ", js}, {"links ", ls}, {"URDF links ", us}})
      if (!list.empty()) out += what + list.substr(2) + "; ";
    return out + "or \"ground\"";
  };
  auto mounting = [&](const ParentRef& pr, bool joint, int index) {
    const Entity self{joint ? Mounting::Kind::Joint : Mounting::Kind::Link, index};
    Mounting on;
    on.X = pr.X;
    if (pr.name.empty()) {
      if (!joint && nl > 1)
        r.fail(pr.node, pr.path + ".parent", "missing: with several links each names its parent (a joint, a link or \"ground\")");
      on.kind = Mounting::Kind::Chain;
    } else if (pr.name == "ground") {
      on.kind = Mounting::Kind::Ground;
    } else {
      const auto it = named.find(pr.name);
      const auto f = std::find_if(c.frames.begin(), c.frames.end(), [&](const BodyFrame& b) { return b.name == pr.name; });
      if (f != c.frames.end()) {  // a URDF link: on the body it is welded to, through its frame
        if (it != named.end() && !(it->second.kind == Mounting::Kind::Joint && it->second.index == f->joint && f->X == Mat4::Identity()))
          r.fail(pr.node, pr.path + ".parent", "'" + pr.name + "' names a URDF link and a " +
                                                   (it->second.kind == Mounting::Kind::Joint ? "joint" : "link") + " of another body: rename one");
        on.kind = f->joint >= 0 ? Mounting::Kind::Joint : Mounting::Kind::Ground;
        on.index = f->joint;
        on.X = f->X * pr.X;
      } else if (it == named.end()) {
        r.fail(pr.node, pr.path + ".parent", "no joint or link named '" + pr.name + "' (" + choices(self) + ")");
      } else if (it->second.kind == self.kind && it->second.index == self.index) {
        // (often a URDF link misnamed as the [link]'s own default name "link")
        r.fail(pr.node, pr.path + ".parent", "'" + pr.name + "' is " + (joint ? "this joint" : "this link") +
                                                 " itself: no other joint or link has that name (" + choices(self) + ")");
      } else {
        on.kind = it->second.kind;
        on.index = it->second.index;
      }
    }
    if (pr.at) {
      if (on.kind != Mounting::Kind::Link)
        r.fail(pr.at, pr.path + ".at", "applies to something mounted on a link only (its parent is not a link)");
      const double L = c.links[on.index].link.total_length();
      if (pr.at->is_string() && pr.at->as_string()->get() == "tip") on.at = L;
      else if (auto f = pr.at->value<double>()) on.at = *f;
      else r.fail(pr.at, pr.path + ".at", "must be a position along the link [m] or \"tip\"");
      if (!std::isfinite(on.at) || on.at < 0.0 || on.at > L * (1 + 1e-12))
        r.fail(pr.at, pr.path + ".at", "must lie on link '" + c.links[on.index].name + "', 0 to " + Reader::fmt(L) +
                                           " m, or be \"tip\" (got " + Reader::fmt(on.at) + ")");
      on.at = std::min(on.at, L);
    } else if (on.kind == Mounting::Kind::Link) {
      on.at = c.links[on.index].link.total_length();
    }
    return on;
  };
  for (int j = 0; j < m; ++j) c.joints[j].on = mounting(joint_parents[j], true, j);
  for (int l = 0; l < nl; ++l) c.links[l].on = mounting(link_parents[l], false, l);
  // The defaults (a link on the last joint of the chain from the ground), the points and the
  // cycles: the model's rule (core/mounting.hpp), reported at the parent key of whom it concerns.
  std::vector<Mounting> jon, lon;
  std::vector<std::string> jn, ln;
  std::vector<double> len;
  for (const Joint& j : c.joints) jon.push_back(j.on), jn.push_back(j.name);
  for (const LinkCase& l : c.links) lon.push_back(l.on), ln.push_back(l.name), len.push_back(l.link.total_length());
  try {
    rfem::resolve_mountings(jon, lon, jn, ln, len);
  } catch (const MountingError& e) {
    const ParentRef& pr = e.joint ? joint_parents[e.index] : link_parents[e.index];
    r.fail(pr.node, pr.path + ".parent", e.what());
  }
  for (int j = 0; j < m; ++j) c.joints[j].on = jon[j];
  for (int l = 0; l < nl; ++l) c.links[l].on = lon[l];
  // A joint under a force input that moves no mass (no body, no drive inertia, nothing mounted on
  // it that has one) has no acceleration the equations of motion can give: its mass matrix row is
  // zero. Refused here, by name, rather than as a singular mass matrix at the first step.
  std::vector<char> moves(m, 0);  // whether joint j moves some mass or inertia
  for (int l = 0; l < nl; ++l)
    if (c.links[l].on.kind == Mounting::Kind::Joint) moves[c.links[l].on.index] = 1;
  for (bool changed = true; changed;) {  // up the tree (no cycles: resolve_mountings)
    changed = false;
    for (int j = 0; j < m; ++j) {
      const Joint& J = c.joints[j];
      const bool own = J.H.cwiseAbs().maxCoeff() > 0.0 || J.drive.inertia > 0.0;
      if ((own || moves[j]) && J.on.kind == Mounting::Kind::Joint && !moves[J.on.index]) moves[J.on.index] = 1, changed = true;
      if (own && !moves[j]) moves[j] = 1, changed = true;
    }
  }
  for (int j = 0; j < m; ++j) {
    if (moves[j] || (j < static_cast<int>(c.inputs.size()) && c.inputs[j].prescribed())) continue;
    const ParentRef& pr = joint_parents[j];
    const bool urdf = pr.path == "base.urdf";
    r.fail(pr.node, urdf ? "base.joints." + c.joints[j].name : pr.path,
           "joint '" + c.joints[j].name + "' moves no mass: it has no " + (urdf ? "inertial in the URDF" : "body") +
               ", no drive inertia, and nothing with mass is mounted on it, so under its force input (" +
               to_string(c.inputs[j].kind) + ") its acceleration is undetermined; give it a body or drive.inertia, "
               "mount something on it, or give it a motion input");
  }
  // A joint left without a parent sits on the previous joint; where a link sits there too, the
  // joint was often meant to sit on that link (an elbow on the upper arm's tip): say so.
  for (int j = 1; j < m; ++j) {
    const ParentRef& pr = joint_parents[j];
    if (!pr.name.empty() || pr.path == "base" || c.joints[j].on.kind != Mounting::Kind::Joint) continue;
    for (int l = 0; l < nl; ++l)
      if (c.links[l].on.kind == Mounting::Kind::Joint && c.links[l].on.index == j - 1) {
        const std::string& prev = c.joints[j - 1].name;
        r.warn(pr.node, pr.path + ".parent",
               "missing: joint '" + c.joints[j].name + "' sits on the previous joint '" + prev + "', where link '" +
                   c.links[l].name + "' sits too; to mount it on that link write parent = \"" + c.links[l].name +
                   "\" (at its tip), or parent = \"" + prev + "\" to keep it where it is");
        break;
      }
  }
}

}  // namespace rfem::reading
