#include "sensors.hpp"

#include <cmath>
#include <stdexcept>

#include "../core/positions.hpp"

namespace rfem {

SensorBank::SensorBank(const Case& cs, const Model& model) : model_(model) {
  for (const SensorSpec& s : cs.sensors) {
    Resolved r;
    r.spec = s;
    for (int k = 0; k < 2; ++k) {
      r.random[k].seed = static_cast<unsigned long long>(s.seed) * 2 + static_cast<unsigned long long>(k);
      r.random[k].engine.seed(r.random[k].seed);
    }
    if (!s.joint.empty()) {
      for (int j = 0; j < model.m(); ++j)
        if (model.joints[j].name == s.joint) r.joint = j;
      if (r.joint < 0) throw std::invalid_argument(s.where + ": no joint '" + s.joint + "' in the model");
    }
    if (!s.link.empty()) {
      for (size_t l = 0; l < model.links.size(); ++l)
        if (model.links[l].name == s.link) r.link = static_cast<int>(l);
      if (r.link < 0) throw std::invalid_argument(s.where + ": no link '" + s.link + "' in the model");
    }
    if (s.kind == SensorSpec::Kind::Strain) {
      // The sde nearest the gauge: RFEM's bending moment lives at the sdes (docs/formulation.md §3).
      // A rigid link (the paper procedure's rigid run) has none: the gauge reads NaN there.
      const Discretisation& d = model.links[static_cast<size_t>(r.link)].d;
      double best = INFINITY;
      for (size_t e = 0; e < d.sdes.size(); ++e)
        if (std::abs(d.sdes[e].position - s.at) < best) {
          best = std::abs(d.sdes[e].position - s.at);
          r.sde = static_cast<int>(e);
        }
      if (r.sde < 0) {
        sensors_.push_back(std::move(r));
        continue;
      }
      const int l = cs.link_index(s.link);
      const Segment& seg = cs.links[static_cast<size_t>(l)].link.segments.at(static_cast<size_t>(d.sdes[r.sde].segment));
      r.EI = seg.material.E * (s.face == 'z' ? seg.section.Iy : seg.section.Iz);
    }
    sensors_.push_back(std::move(r));
  }
}

int SensorBank::width(size_t i) const {
  switch (sensors_[i].spec.kind) {
    case SensorSpec::Kind::Encoder: return 2;
    case SensorSpec::Kind::Tip: return 3;
    case SensorSpec::Kind::Imu: return 6;
    default: return 1;
  }
}

std::vector<std::string> SensorBank::columns() const {
  std::vector<std::string> c;
  for (const Resolved& r : sensors_) {
    const std::string& n = r.spec.name;
    switch (r.spec.kind) {
      case SensorSpec::Kind::Encoder: c.insert(c.end(), {n + "/q", n + "/qd"}); break;
      case SensorSpec::Kind::Tip:
        if (r.spec.quantity == "deflection") c.insert(c.end(), {n + "/u1", n + "/u2", n + "/theta"});
        else c.insert(c.end(), {n + "/x", n + "/y", n + "/z"});
        break;
      case SensorSpec::Kind::Imu: c.insert(c.end(), {n + "/wx", n + "/wy", n + "/wz", n + "/fx", n + "/fy", n + "/fz"}); break;
      default: c.push_back(n);
    }
  }
  return c;
}

std::vector<std::string> SensorBank::units() const {
  std::vector<std::string> u;
  for (const Resolved& r : sensors_) {
    const bool prismatic = r.joint >= 0 && model_.joints[static_cast<size_t>(r.joint)].type == JointType::Prismatic;
    switch (r.spec.kind) {
      case SensorSpec::Kind::Encoder: u.insert(u.end(), {prismatic ? "m" : "rad", prismatic ? "m/s" : "rad/s"}); break;
      case SensorSpec::Kind::Torque: u.push_back(prismatic ? "N" : "N m"); break;
      case SensorSpec::Kind::Tip: {
        const std::string& k = r.spec.quantity;
        if (k == "deflection") u.insert(u.end(), {"m", "m", "rad"});
        else u.insert(u.end(), 3, k == "position" ? "m" : k == "velocity" ? "m/s" : "m/s2");
        break;
      }
      case SensorSpec::Kind::Strain: u.push_back("1"); break;
      case SensorSpec::Kind::Imu: u.insert(u.end(), {"rad/s", "rad/s", "rad/s", "m/s2", "m/s2", "m/s2"}); break;
    }
  }
  return u;
}

void SensorBank::read(const VecX& q, const VecX& v, const VecX& a, const VecX& tau, std::vector<double>& out, int stream) {
  for (Resolved& r : sensors_) {
    const size_t first = out.size();
    switch (r.spec.kind) {
      case SensorSpec::Kind::Encoder:
        out.push_back(q[model_.joint_index(r.joint)]);
        out.push_back(v[model_.joint_index(r.joint)]);
        break;
      case SensorSpec::Kind::Torque: out.push_back(tau[r.joint]); break;
      case SensorSpec::Kind::Tip: {
        if (r.spec.quantity == "deflection") {
          const Vec3 u = tip_deflection(model_, r.link, q);
          out.insert(out.end(), {u[0], u[1], u[2]});
          break;
        }
        const PointMotion m = point_motion(model_, r.link, model_.links[static_cast<size_t>(r.link)].d.length, q, v, a);
        const bool link = r.spec.frame == "link";
        const Mat3 axes = link ? Mat3(m.frame.topLeftCorner<3, 3>().transpose()) : Mat3::Identity();
        Vec3 x = r.spec.quantity == "position" ? m.position : r.spec.quantity == "velocity" ? m.velocity : m.acceleration;
        if (link && r.spec.quantity == "position") x -= m.frame.topRightCorner<3, 1>();
        x = axes * x;
        out.insert(out.end(), {x[0], x[1], x[2]});
        break;
      }
      case SensorSpec::Kind::Imu: {
        // Strapdown: the body's rate and the specific force a − g, both in the body's axes (at rest
        // under gravity an accelerometer reads +g upwards).
        const PointMotion m = point_motion(model_, r.link, r.spec.at, q, v, a);
        const Vec3 w = m.rotation.transpose() * m.angular_velocity;
        const Vec3 f = m.rotation.transpose() * (m.acceleration - Vec3(0.0, 0.0, -model_.gravity));
        out.insert(out.end(), {w[0], w[1], w[2], f[0], f[1], f[2]});
        break;
      }
      case SensorSpec::Kind::Strain: {
        // M = k Δφ about the gauge's bending axis (the sde's rotational spring), ε = M c / (E I):
        // a fibre towards +z is stretched by a positive Δφ about y, one towards +y by a negative
        // Δφ about z (x turns towards −z, resp. +y).
        if (r.sde < 0) {
          out.push_back(NAN);
          break;
        }
        const MountedLink& L = model_.links[static_cast<size_t>(r.link)];
        const Sde& e = L.d.sdes[static_cast<size_t>(r.sde)];
        const int a = r.spec.face == 'z' ? 4 : 5;  // φ2 or φ3 among an rfe's six coordinates
        const double right = q[model_.rfe_index(r.link, e.right) + a];
        const double left = e.left >= 0 ? q[model_.rfe_index(r.link, e.left) + a] : 0.0;
        const double M = e.k[a - 3] * (right - left);
        out.push_back((r.spec.face == 'z' ? 1.0 : -1.0) * M * r.spec.distance / r.EI);
        break;
      }
    }
    if (stream >= 0) measure(r, out.data() + first, out.size() - first, stream);
  }
}

void SensorBank::measure(Resolved& r, double* x, size_t count, int stream) {
  std::normal_distribution<double> noise(0.0, 1.0);
  for (size_t i = 0; i < count; ++i) {
    if (r.spec.noise > 0) x[i] += r.spec.noise * noise(r.random[stream]);
    if (r.spec.quantum > 0) x[i] = r.spec.quantum * std::round(x[i] / r.spec.quantum);
  }
}

void SensorBank::skip(int stream) {
  std::vector<double> x;
  for (size_t i = 0; i < sensors_.size(); ++i) {
    x.assign(static_cast<size_t>(width(i)), 0.0);
    measure(sensors_[i], x.data(), x.size(), stream);  // (the draws do not depend on the values)
  }
}

std::vector<double> SensorBank::save() const {
  std::vector<double> x;  // (counts are exact as doubles below 2⁵³)
  for (const Resolved& r : sensors_)
    for (const Stream& st : r.random) x.push_back(static_cast<double>(st.drawn));
  return x;
}

void SensorBank::restore(const std::vector<double>& x) {
  if (x.size() != 2 * sensors_.size())
    throw std::invalid_argument("the sensors' random streams: " + std::to_string(x.size() / 2) + " sensors saved, the case has " +
                                std::to_string(sensors_.size()));
  for (double c : x)
    if (!(c >= 0 && c <= 9007199254740992.0 && c == std::floor(c)))
      throw std::invalid_argument("the sensors' random streams: a count that is not a whole number ≥ 0");
  size_t i = 0;
  for (Resolved& r : sensors_)
    for (Stream& st : r.random) {
      const auto want = static_cast<unsigned long long>(x[i++]);
      if (want < st.drawn) {  // (an engine goes forward only: from its seed again)
        st.engine.seed(st.seed);
        st.drawn = 0;
      }
      st.engine.discard(want - st.drawn);
      st.drawn = want;
    }
}

}  // namespace rfem
