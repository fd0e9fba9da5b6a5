// Materials, sections, rigid bodies and joint drives of a case file.
#include <cmath>

#include "case_reading_impl.hpp"
#include "../core/rotation.hpp"

namespace rfem::reading {

Mat4 transform(const Reader& r, const toml::table& t, const std::string& path) {
  r.check_keys(t, path, {"xyz", "rpy"});
  return homogeneous(rot_rpy(r.vec3(t, path, "rpy", Vec3::Zero())), r.vec3(t, path, "xyz", Vec3::Zero()));
}

Mat4 read_mount(const Reader& r, const toml::table& t, const std::string& path) {
  const toml::node* mn = t.get("mount");
  if (!mn) return Mat4::Identity();
  if (!mn->is_table()) r.fail(mn, path + ".mount", "must be a table {xyz, rpy}");
  return transform(r, *mn->as_table(), path + ".mount");
}

namespace {

Material read_material(const Reader& r, const toml::table& t, const std::string& path, const std::string& name) {
  r.check_keys(t, path, {"E", "G", "rho"});
  Material m;
  m.name = name;
  m.E = r.ranged(t, path, "E", 1.0, 1e20, "Pa");
  m.G = r.ranged(t, path, "G", 1.0, 1e20, "Pa");
  m.rho = r.ranged(t, path, "rho", 1e-3, 1e6, "kg/m^3");
  // Each value against what real materials span (kPlausible*), before any ratio of two: a ratio
  // with a slipped unit would blame the sound one (E = 70 Pa made G > E/2).
  if (m.E < kPlausibleE.lo)
    r.doubt(t.get("E"), path + ".E", "E = " + Reader::fmt(m.E) +
                                         " Pa is very small: units are SI (Pa), not GPa or MPa (the softest solids a link is made of have about 1e5 Pa)");
  if (m.E > kPlausibleE.hi) r.doubt(t.get("E"), path + ".E", "E = " + Reader::fmt(m.E) + " Pa is stiffer than diamond (1.2e12 Pa): units are Pa");
  if (m.G < kPlausibleG.lo)
    r.doubt(t.get("G"), path + ".G", "G = " + Reader::fmt(m.G) +
                                         " Pa is very small: units are SI (Pa), not GPa or MPa (soft elastomers have about 3e4 Pa)");
  if (m.G > kPlausibleG.hi) r.doubt(t.get("G"), path + ".G", "G = " + Reader::fmt(m.G) + " Pa is stiffer than diamond (5e11 Pa): units are Pa");
  if (m.rho < kPlausibleRho.lo)
    r.doubt(t.get("rho"), path + ".rho", "rho = " + Reader::fmt(m.rho) +
                                             " kg/m^3 is very small: units are SI (kg/m^3), not g/cm^3 (the lightest structural foams have 10 kg/m^3)");
  if (m.rho > kPlausibleRho.hi)
    r.doubt(t.get("rho"), path + ".rho", "rho = " + Reader::fmt(m.rho) + " kg/m^3 is denser than any material (osmium: 2.26e4): units are kg/m^3");
  if (kPlausibleE.holds(m.E) && kPlausibleG.holds(m.G) && m.G > m.E / 2)
    r.warn(t.get("G"), path + ".G", "G > E/2 means a negative Poisson's ratio (nu = E/2G - 1 = " + Reader::fmt(m.E / (2 * m.G) - 1) + ")");
  return m;
}

Section read_section(const Reader& r, const toml::table& t, const std::string& path, const std::string& name) {
  if (t.get("box")) {
    r.check_keys(t, path, {"box", "kappa_y", "kappa_z"});
    const toml::table& b = r.table(t, path, "box");
    const std::string bp = path + ".box";
    r.check_keys(b, bp, {"outer", "inner"});
    const double outer = r.ranged(b, bp, "outer", 1e-6, 1e3, "m"), inner = r.non_negative(b, bp, "inner", 0.0);
    if (inner >= outer) r.fail(b.get("inner"), bp + ".inner", "must be smaller than outer");
    Section s = box_section(name, outer, inner);
    s.kappa_y = r.positive(t, path, "kappa_y", s.kappa_y);
    s.kappa_z = r.positive(t, path, "kappa_z", s.kappa_z);
    return s;
  }
  r.check_keys(t, path, {"A", "Iy", "Iz", "J", "kappa_y", "kappa_z", "offset_y", "offset_z"});
  Section s;
  s.name = name;
  s.A = r.ranged(t, path, "A", 1e-14, 1e4, "m^2");
  s.Iy = r.ranged(t, path, "Iy", 1e-30, 1e8, "m^4");
  s.Iz = r.ranged(t, path, "Iz", 1e-30, 1e8, "m^4");
  s.J = r.ranged(t, path, "J", 1e-30, 1e8, "m^4");
  if (s.A >= 1.0)
    r.warn(t.get("A"), path + ".A", "A = " + Reader::fmt(s.A) + " m^2 is a cross-section over a metre across: if mm^2 were meant, write " +
                                        Reader::fmt(s.A * 1e-6));
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
  // The disc has the smallest polar moment of all regions of area A: Iy + Iz >= A^2/(2 pi).
  if (s.Iy + s.Iz < 0.9999 * s.A * s.A / (2 * M_PI))
    r.warn(t.get("A"), path + ".A", "A = " + Reader::fmt(s.A) + " m^2 with Iy + Iz = " + Reader::fmt(s.Iy + s.Iz) +
                                        " m^4 is no real section (a disc of that area has " + Reader::fmt(s.A * s.A / (2 * M_PI)) +
                                        "): check the units (m^2, m^4)");
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

}  // namespace

Materials read_materials(const Reader& r, const toml::table& root) {
  return read_named<Material>(r, root, "materials", read_material);
}

Sections read_sections(const Reader& r, const toml::table& root) {
  return read_named<Section>(r, root, "sections", read_section);
}

Mat4 read_body(const Reader& r, const toml::table& t, const std::string& path, const Materials& mats,
               const Sections& secs, const std::set<std::string>& extra) {
  if (t.get("section")) {
    // Uniform prismatic link along its frame's x axis from the origin.
    std::set<std::string> keys{"section", "material", "length"};
    keys.insert(extra.begin(), extra.end());
    r.check_keys(t, path, keys);
    const std::string sn = r.string(t, path, "section"), mn = r.string(t, path, "material");
    if (!secs.count(sn)) r.fail(t.get("section"), path + ".section", "no section named '" + sn + "'");
    if (!mats.count(mn)) r.fail(t.get("material"), path + ".material", "no material named '" + mn + "'");
    const double L = r.ranged(t, path, "length", 1e-6, 1e6, "m");
    const Section& s = secs.at(sn);
    const double rho = mats.at(mn).rho, mass = rho * s.A * L;
    Mat3 I = Mat3::Zero();  // about the mass centre; Ixx from the polar second moment
    I(0, 0) = rho * L * (s.Iy + s.Iz);
    I(1, 1) = mass * L * L / 12.0 + rho * L * s.Iy;
    I(2, 2) = mass * L * L / 12.0 + rho * L * s.Iz;
    const Mat4 H = pseudo_inertia(mass, Vec3(0.5 * L, 0, 0), I);
    if (!H.allFinite()) r.fail(t.get("length"), path + ".length", "the body's mass and inertia overflow (" + Reader::fmt(mass) + " kg)");
    return H;
  }
  std::set<std::string> keys{"mass", "com", "inertia"};
  keys.insert(extra.begin(), extra.end());
  r.check_keys(t, path, keys);
  const double mass = r.non_negative(t, path, "mass", 0.0);
  if (mass > 1e12) r.fail(t.get("mass"), path + ".mass", "must lie within what rfem computes with, 0 to 1e12 kg (got " + Reader::fmt(mass) + ")");
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
  const Mat4 H = pseudo_inertia(mass, com, I);
  if (!H.allFinite()) r.fail(&t, path, "the body's mass and inertia overflow");
  return H;
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
}  // namespace rfem::reading
