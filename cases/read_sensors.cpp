// [[sensors]]: what a lab would measure (cases/sensor_spec.hpp), checked against the case's joints
// and links.
#include <set>

#include "case_reading_impl.hpp"

namespace rfem {

const char* to_string(SensorSpec::Kind k) {
  switch (k) {
    case SensorSpec::Kind::Encoder: return "encoder";
    case SensorSpec::Kind::Torque: return "torque";
    case SensorSpec::Kind::Tip: return "tip";
    case SensorSpec::Kind::Strain: return "strain";
    case SensorSpec::Kind::Imu: return "imu";
  }
  return "?";
}

namespace reading {

std::vector<SensorSpec> read_sensors(const Reader& r, const toml::table& root, const Case& c) {
  std::vector<SensorSpec> out;
  const toml::node* sn = root.get("sensors");
  if (!sn) return out;
  const toml::array* arr = sn->as_array();
  if (!arr) r.fail(sn, "sensors", "must be an array of tables ([[sensors]])");
  // Names the snapshot a controller sees already uses (simulation/simulation.hpp, Snapshot).
  const std::set<std::string> reserved = {"t", "q", "qd", "tau", "tip_position", "tip_deflection", "time"};
  std::set<std::string> names;
  for (size_t i = 0; i < arr->size(); ++i) {
    const toml::node* e = arr->get(i);
    const std::string p = "sensors." + std::to_string(i);
    if (!e->is_table()) r.fail(e, p, "must be a table");
    const toml::table& t = *e->as_table();
    SensorSpec s;
    s.where = r.file() + (e->source().begin.line > 0 ? ":" + std::to_string(e->source().begin.line) : "") + ": " + p;
    s.name = r.string(t, p, "name");
    if (const std::string why = name_problem(s.name); !why.empty()) r.fail(t.get("name"), p + ".name", why);
    if (reserved.count(s.name)) r.fail(t.get("name"), p + ".name", "'" + s.name + "' is a name the snapshot uses already");
    if (!names.insert(s.name).second) r.fail(t.get("name"), p + ".name", "another sensor is named '" + s.name + "'");
    const std::string kind = r.string(t, p, "kind");
    std::set<std::string> keys = {"name", "kind", "noise", "quantum", "seed"};
    if (kind == "encoder" || kind == "torque") {
      s.kind = kind == "encoder" ? SensorSpec::Kind::Encoder : SensorSpec::Kind::Torque;
      keys.insert("joint");
      s.joint = r.string(t, p, "joint");
      bool known = false;
      std::string list;
      for (const Joint& j : c.joints) {
        known |= j.name == s.joint;
        list += (list.empty() ? "" : ", ") + j.name;
      }
      if (!known) r.fail(t.get("joint"), p + ".joint", "no joint named '" + s.joint + "' (joints: " + list + ")");
    } else if (kind == "tip" || kind == "strain" || kind == "imu") {
      s.kind = kind == "tip" ? SensorSpec::Kind::Tip : kind == "strain" ? SensorSpec::Kind::Strain : SensorSpec::Kind::Imu;
      s.link = c.links.size() == 1 && !t.get("link") ? c.links[0].name : r.string(t, p, "link");
      keys.insert("link");
      const int l = c.link_index(s.link);
      if (l < 0) {
        std::string list;
        for (const auto& L : c.links) list += (list.empty() ? "" : ", ") + L.name;
        r.fail(t.get("link") ? t.get("link") : e, p + ".link",
               "no flexible link named '" + s.link + "'" + (list.empty() ? " (the case has none)" : " (links: " + list + ")"));
      }
      const double L = c.links[static_cast<size_t>(l)].link.total_length();
      if (s.kind == SensorSpec::Kind::Tip) {
        keys.insert({"quantity", "frame"});
        s.quantity = r.string(t, p, "quantity", "deflection");
        if (s.quantity != "deflection" && s.quantity != "position" && s.quantity != "velocity" && s.quantity != "acceleration")
          r.fail(t.get("quantity"), p + ".quantity",
                 "\"deflection\" (u1, u2, theta in the link's frame), \"position\", \"velocity\" or \"acceleration\" (got \"" + s.quantity + "\")");
        if (s.quantity == "deflection" && t.get("frame"))
          r.fail(t.get("frame"), p + ".frame", "a deflection is in the link's frame already (frame is for position, velocity, acceleration)");
        s.frame = r.string(t, p, "frame", "world");
        if (s.frame != "world" && s.frame != "link")
          r.fail(t.get("frame"), p + ".frame", "\"world\" (the axes of {0}) or \"link\" (of the link's frame {r}) (got \"" + s.frame + "\")");
      } else if (s.kind == SensorSpec::Kind::Imu) {
        keys.insert("at");
        s.at = r.non_negative(t, p, "at", L);
        if (s.at > L) r.fail(t.get("at"), p + ".at", "beyond the link's length " + Reader::fmt(L) + " m");
      } else {
        keys.insert({"at", "face", "distance"});
        s.at = r.non_negative(t, p, "at", 0.0);
        if (s.at > L) r.fail(t.get("at"), p + ".at", "beyond the link's length " + Reader::fmt(L) + " m");
        const std::string face = r.string(t, p, "face", "z");
        if (face != "y" && face != "z")
          r.fail(t.get("face"), p + ".face", "\"z\" (the gauge towards +z: bending about y) or \"y\" (towards +y: bending about z)");
        s.face = face[0];
        s.distance = r.non_negative(t, p, "distance", 0.0);
        if (!t.get("distance")) r.fail(e, p + ".distance", "missing: the gauge's distance from the elastic axis [m]");
      }
    } else {
      r.fail(t.get("kind"), p + ".kind", "\"encoder\", \"torque\", \"tip\", \"strain\" or \"imu\" (got \"" + kind + "\")");
    }
    r.check_keys(t, p, keys);
    s.noise = r.non_negative(t, p, "noise", 0.0);
    s.quantum = r.non_negative(t, p, "quantum", 0.0);
    s.seed = r.integer(t, p, "seed", static_cast<long>(i) + 1, 0, 1L << 62);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace reading
}  // namespace rfem
