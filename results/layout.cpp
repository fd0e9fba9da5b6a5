#include "layout.hpp"

#include "../core/check.hpp"
#include "../core/positions.hpp"

namespace rfem {

int RunLayout::find(const std::string& name) const {
  for (size_t i = 0; i < series.size(); ++i)
    if (series[i].name == name) return static_cast<int>(i);
  return -1;
}

RunLayout run_layout(const Model& model, int flexible_every) {
  RFEM_CHECK_ARGUMENT(flexible_every >= 0, "flexible_every must not be negative");
  RunLayout out;
  out.flexible_every = flexible_every;
  const int n = model.n();
  std::vector<std::string> jn, ju, rate, acc, tau, jp, jpu;
  for (const auto& j : model.joints) {
    const bool rev = j.type == JointType::Revolute;
    jn.push_back(j.name);
    ju.push_back(rev ? "rad" : "m");
    rate.push_back(rev ? "rad/s" : "m/s");
    acc.push_back(rev ? "rad/s^2" : "m/s^2");
    tau.push_back(rev ? "N m" : "N");
    for (const char* c : {".x", ".y", ".z"}) {
      jp.push_back(j.name + c);
      jpu.push_back("m");
    }
  }
  auto add = [](std::vector<SeriesInfo>& to, const std::string& name, std::vector<std::string> columns,
                std::vector<std::string> units, const std::string& description = "") {
    if (columns.empty()) {  // (a model without joints keeps one zero column)
      columns = {"(none)"};
      units = {""};
    }
    to.push_back({name, std::move(columns), std::move(units), description});
  };
  auto& S = out.series;
  add(S, "time", {"t"}, {"s"});
  add(S, "joint_q", jn, ju, "joint coordinates");
  add(S, "joint_v", jn, rate, "joint rates");
  add(S, "joint_a", jn, acc, "joint accelerations (of the integrator's continuous solution)");
  add(S, "joint_tau", jn, tau, "applied torque/force (force input) or required (kinematic input)");
  add(S, "joint_position", jp, jpu, "origin of each joint's frame (of the body it moves) in the inertial frame {0}");
  add(S, "energy", {"kinetic", "elastic", "gravity", "input_work", "dissipated", "balance"}, {"J", "J", "J", "J", "J", "J"},
      "balance = kinetic + elastic + gravity + dissipated - input_work");
  add(S, "momentum", {"px", "py", "pz", "Lx", "Ly", "Lz"}, {"kg m/s", "kg m/s", "kg m/s", "kg m2/s", "kg m2/s", "kg m2/s"},
      "linear momentum and angular momentum about the origin of {0} of every body (drive rotors left out)");
  add(S, "centre_of_mass", {"x", "y", "z"}, {"m", "m", "m"}, "centre of mass of every body in {0}");
  const bool flexible = flexible_every > 0 && n > 0;
  if (flexible) add(out.flexible, "flexible_time", {"t"}, {"s"});
  for (const MountedLink& L : model.links) {
    const std::string g = "links/" + L.name + "/";
    add(S, g + "tip", {"ux", "uy", "uz", "rx", "ry", "rz"}, {"m", "m", "m", "rad", "rad", "rad"},
        "free end on the elastic axis: displacement from undeformed and rotation φ of rfe_n, in {r} axes");
    add(S, g + "tip_position", {"x", "y", "z"}, {"m", "m", "m"}, "free end on the elastic axis, in the inertial frame {0}");
    add(S, g + "tip_deflection", {"u1", "u2", "theta"}, {"m", "m", "rad"},
        "the paper's tip deflections: u1 along y of {r}, u2 along z of {r}, theta the torsion phi1 of rfe_n");
    if (!L.d.payloads.empty()) {
      std::vector<std::string> cols, units;
      for (size_t i = 1; i <= L.d.payloads.size(); ++i)
        for (const char* c : {".x", ".y", ".z"}) {
          cols.push_back("payload" + std::to_string(i) + c);
          units.push_back("m");
        }
      add(S, g + "payload_position", cols, units, "reference point of each payload (on the elastic axis) in {0}");
    }
    if (flexible) {  // the pose of the link's elastic axis (rfem view, rfem animate)
      std::vector<std::string> cols, units;
      const int P = static_cast<int>(axis_stations(model, static_cast<int>(&L - model.links.data())).size());
      for (int k = 0; k < P; ++k)
        for (const char* c : {".x", ".y", ".z"}) {
          cols.push_back((k == 0 ? std::string("start") : k == P - 1 ? std::string("tip") : "rfe" + std::to_string(k)) + c);
          units.push_back("m");
        }
      add(out.flexible, g + "axis_position", cols, units,
          "points of the elastic axis in {0}: the link's start, the mass centre station of every rfe, its free end");
      add(out.flexible, g + "axis_deflection", cols, units,
          "displacement of the axis_position points from the undeformed axis, in {0} axes");
      std::vector<std::string> rc, ru;
      for (int k = 0; k < P; ++k)
        for (const char* c : {".R11", ".R12", ".R13", ".R21", ".R22", ".R23", ".R31", ".R32", ".R33"}) {
          rc.push_back((k == 0 ? std::string("start") : k == P - 1 ? std::string("tip") : "rfe" + std::to_string(k)) + c);
          ru.push_back("1");
        }
      add(out.flexible, g + "axis_rotation", rc, ru,
          "orientation of the body each axis_position point moves with: rotation matrix to {0}, row by row "
          "(its columns are that body's x, y, z axes; {r} at the start, the rfe's frame, the last rfe's at the tip)");
    }
    if (L.n() == 0) continue;
    if (flexible) {
      std::vector<std::string> cols, units;
      for (int k = 1; k <= L.n(); ++k)
        for (const char* c : {"x1", "x2", "x3", "phi1", "phi2", "phi3"}) {
          cols.push_back("rfe" + std::to_string(k) + "." + c);
          units.push_back(c[0] == 'x' ? "m" : "rad");
        }
      add(out.flexible, g + "flexible_q", cols, units,
          "rfe coordinates [2.2]: mass-centre displacement from rfe_centre and angles of R = RotY(phi2) "
          "RotZ(phi3) RotX(phi1), in {r} axes");
    }
    std::vector<double> c;  // the undeformed mass centres in {r}: flexible_q is relative to these
    for (const auto& r : L.d.rfes) c.insert(c.end(), {r.centre[0], r.centre[1], r.centre[2]});
    out.constants.push_back({{g + "rfe_centre", {"x", "y", "z"}, {"m", "m", "m"}, "undeformed mass centre of rfe k (row k-1) in {r}"},
                             std::move(c)});
  }
  if (!model.links.empty()) {
    const std::string g = "links/" + model.links.back().name + "/";
    auto exists = [&](const std::string& name) {
      for (const auto* v : {&out.series, &out.flexible})
        for (const SeriesInfo& s : *v)
          if (s.name == name) return true;
      for (const auto& [s, values] : out.constants)
        if (s.name == name) return true;
      return false;
    };
    for (const char* d : {"tip", "tip_position", "tip_deflection", "rfe_centre", "flexible_q", "payload_position"})
      if (exists(g + d)) out.aliases.push_back({d, g + d});
  }
  return out;
}

void sample_rows(const Model& model, const RunLayout& layout, const OutputSample& s, std::vector<std::vector<double>>& rows) {
  RFEM_CHECK_ARGUMENT_SIZE(s.q.size(), model.dof(), "sample q");
  rows.resize(layout.series.size());
  size_t i = 0;
  auto put = [&](const double* x, int k) { rows[i++].assign(x, x + k); };
  const int m = model.m();
  put(&s.t, 1);
  if (m > 0) {
    const VecX qb = model.joint_coords(s.q), vb = model.joint_coords(s.v), ab = model.joint_coords(s.a);
    put(qb.data(), m);
    put(vb.data(), m);
    put(ab.data(), m);
    put(s.tau.data(), m);
    std::vector<double> flat;
    for (const Vec3& p : joint_positions(model, s.q)) flat.insert(flat.end(), {p[0], p[1], p[2]});
    put(flat.data(), 3 * m);
  } else {
    const double z = 0.0;
    for (int k = 0; k < 5; ++k) put(&z, 1);
  }
  const double e[6] = {s.energy.kinetic, s.energy.elastic, s.energy.gravity, s.input_work, s.dissipated, s.energy_balance()};
  put(e, 6);
  const double mom[6] = {s.momentum.linear.x(),  s.momentum.linear.y(),  s.momentum.linear.z(),
                         s.momentum.angular.x(), s.momentum.angular.y(), s.momentum.angular.z()};
  put(mom, 6);
  put(s.momentum.centre.data(), 3);
  for (int l = 0; l < static_cast<int>(model.links.size()); ++l) {
    const MountedLink& L = model.links[l];
    const Vec6 tip = tip_motion(model, l, s.q);
    put(tip.data(), 6);
    const Vec3 p = tip_position(model, l, s.q);
    put(p.data(), 3);
    const Vec3 u = tip_deflection(model, l, s.q);
    put(u.data(), 3);
    if (!L.d.payloads.empty()) {
      std::vector<double> flat;
      for (const Payload& pl : L.d.payloads) {
        const Vec3 x = point_position(model, l, pl.at, s.q);
        flat.insert(flat.end(), {x[0], x[1], x[2]});
      }
      put(flat.data(), static_cast<int>(flat.size()));
    }
  }
}

void flexible_rows(const Model& model, const RunLayout& layout, const OutputSample& s,
                   std::vector<std::vector<double>>& rows) {
  rows.resize(layout.flexible.size());
  if (layout.flexible.empty()) return;
  rows[0].assign(1, s.t);
  size_t i = 1;
  for (int l = 0; l < static_cast<int>(model.links.size()); ++l) {
    const MountedLink& L = model.links[l];
    {
      std::vector<Vec3> pos, def;
      std::vector<Mat3> rot;
      axis_points(model, l, axis_stations(model, l), s.q, pos, def, &rot);
      for (const auto* v : {&pos, &def}) {
        std::vector<double>& row = rows[i++];
        row.clear();
        for (const Vec3& p : *v) row.insert(row.end(), {p[0], p[1], p[2]});
      }
      std::vector<double>& row = rows[i++];
      row.clear();
      for (const Mat3& R : rot)
        for (int a = 0; a < 3; ++a) row.insert(row.end(), {R(a, 0), R(a, 1), R(a, 2)});
    }
    if (L.n() == 0) continue;
    std::vector<double>& row = rows[i++];
    row.resize(6 * L.n());
    for (int k = 0; k < L.n(); ++k) Eigen::Map<Vec6>(row.data() + 6 * k) = s.q.segment<6>(model.rfe_index(l, k));
  }
}

}  // namespace rfem
