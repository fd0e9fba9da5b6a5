// Joints of a case file: [[joints]] with their bodies, drives and inputs, and a free-floating base.
#include <cmath>
#include <fstream>

#include "case_reading_impl.hpp"

namespace rfem::reading {


InputSpec read_input(const Reader& r, const toml::table& t, const std::string& path, const std::string& case_dir) {
  InputSpec in;
  std::ostringstream where;  // (ostringstream: GCC 12 warns falsely on ":" + std::to_string)
  where << r.file();
  if (t.source().begin.line) where << ":" << t.source().begin.line;
  where << ": " << path;
  in.where = where.str();
  const std::string kind = r.string(t, path, "kind");
  if (!parse(kind, in.kind))
    r.fail(t.get("kind"), path + ".kind", "unknown input '" + kind + "' (" + input_kind_names() + ")");
  auto file_key = [&]() {
    const std::string f = r.string(t, path, "file");
    in.file = (f.empty() || f[0] == '/') ? f : case_dir + f;
    if (!std::ifstream(in.file)) r.fail(t.get("file"), path + ".file", "cannot open '" + in.file + "'");
  };
  if (in.kind == InputKind::Deployment) {
    r.check_keys(t, path, {"kind", "alpha", "T"});
    in.alpha = r.number(t, path, "alpha");
    in.T = r.positive(t, path, "T");
  } else if (in.kind == InputKind::Spinup) {
    r.check_keys(t, path, {"kind", "Omega", "T"});
    in.Omega = r.number(t, path, "Omega");
    in.T = r.positive(t, path, "T");
  } else if (in.kind == InputKind::ConstantRate) {
    r.check_keys(t, path, {"kind", "rate"});
    in.rate = r.number(t, path, "rate");
  } else if (in.kind == InputKind::Table || in.kind == InputKind::TorqueTable) {
    r.check_keys(t, path, {"kind", "file"});
    file_key();
  } else if (in.kind == InputKind::Torque) {
    r.check_keys(t, path, {"kind", "value"});
    in.value = r.number(t, path, "value", 0.0);
  } else if (in.kind == InputKind::TorqueFromRun) {
    r.check_keys(t, path, {"kind", "file", "run", "joint"});
    file_key();
    in.run = r.string(t, path, "run");
    in.joint = static_cast<int>(r.integer(t, path, "joint", 0, 1, 1000));
  } else if (in.kind == InputKind::Pd) {
    r.check_keys(t, path, {"kind", "reference", "kp", "kd", "feedforward", "sample_time", "delay"});
    const toml::node* rn = t.get("reference");
    if (!rn || !rn->is_table())
      r.fail(rn ? rn : &t, path + ".reference", "a PD input needs a reference motion {kind = \"deployment\", …}");
    in.reference = std::make_shared<InputSpec>(read_input(r, *rn->as_table(), path + ".reference", case_dir));
    if (!in.reference->prescribed())
      r.fail(rn, path + ".reference.kind", "the reference must be a motion (deployment, spinup, constant_rate, table)");
    in.kp = r.non_negative(t, path, "kp", 0.0);
    in.kd = r.non_negative(t, path, "kd", 0.0);
    if (t.get("sample_time")) in.sample_time = r.positive(t, path, "sample_time");  // (0: the continuous law)
    in.delay = static_cast<int>(r.integer(t, path, "delay", 0, 0, 1000000));
    if (in.delay > 0 && in.sample_time <= 0)
      r.fail(t.get("delay"), path + ".delay", "a delay of whole samples needs a sample_time");
    const std::string ff = r.string(t, path, "feedforward", std::string("none"));
    if (!parse(ff, in.feedforward))
      r.fail(t.get("feedforward"), path + ".feedforward", "must be \"none\" or \"rigid\" (got \"" + ff + "\")");
  }
  return in;
}


void read_joints(const Reader& r, const toml::table& root, const Materials& mats, const Sections& secs,
                 const std::string& case_dir, Case& c, std::vector<ParentRef>& parents) {
  const toml::node* jn = root.get("joints");
  if (!jn) return;
  auto arr = jn->as_array();
  if (!arr || !arr->is_array_of_tables()) r.fail(jn, "joints", "must be an array of tables ([[joints]])");
  c.joint_values.resize(static_cast<long>(arr->size()));
  c.joint_rates.resize(static_cast<long>(arr->size()));
  for (size_t i = 0; i < arr->size(); ++i) {
    const toml::table& jt = *arr->get(i)->as_table();
    const std::string p = "joints." + std::to_string(i);
    r.check_keys(jt, p, {"name", "type", "alpha", "a", "theta", "d", "axis", "value", "rate", "body", "drive", "input",
                         "parent", "at", "mount"});
    Joint j;
    j.name = r.string(jt, p, "name", "joint" + std::to_string(i + 1));
    if (const std::string why = name_problem(j.name); !why.empty()) r.fail(jt.get("name"), p + ".name", why);
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
      where << r.file() << ":" << jt.source().begin.line << ": " << p << ".input";
      in.where = where.str();
    }
    if (const toml::node* inn = jt.get("input")) {
      if (!inn->is_table()) r.fail(inn, p + ".input", "must be a table {kind = …}");
      in = read_input(r, *inn->as_table(), p + ".input", case_dir);
    }
    ParentRef pr;
    pr.path = p;
    pr.node = jt.get("parent") ? jt.get("parent") : &jt;
    pr.name = r.string(jt, p, "parent", std::string());
    pr.at = jt.get("at");
    pr.X = read_mount(r, jt, p);
    parents.push_back(pr);
    c.inputs.push_back(in);
    c.joints.push_back(j);
  }
}

// at the given pose and rates; the bus body rides on the last.
void read_base(const Reader& r, const toml::node* bn, const Materials& mats, const Sections& secs,
               const std::string& path, const std::string& case_dir, Case& c, std::vector<ParentRef>& parents) {
  if (!bn->is_table()) r.fail(bn, "base", "must be a table {kind = \"free\", body = …} or {urdf = \"arm.urdf\"}");
  const toml::table& bt = *bn->as_table();
  if (bt.get("urdf")) {
    r.check_keys(bt, "base", {"kind", "urdf", "joints"});
    if (r.string(bt, "base", "kind", std::string("fixed")) != "fixed")
      r.fail(bt.get("kind"), "base.kind", "a URDF base is fixed: its root link is the ground");
    read_urdf_base(r, bt, case_dir, c, parents);
    return;
  }
  if (bt.get("joints")) r.fail(bt.get("joints"), "base.joints", "applies to a URDF base only ([base] urdf = \"…\")");
  r.check_keys(bt, "base", {"kind", "body", "position", "velocity", "yaw", "pitch", "roll", "yaw_rate", "pitch_rate",
                            "roll_rate", "urdf"});
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
  std::vector<ParentRef> chain(free_base_dofs);  // each on the one before, the first on the ground
  for (int i = 0; i < free_base_dofs; ++i) chain[i].path = "base";
  chain[0].name = "ground";
  parents.insert(parents.begin(), chain.begin(), chain.end());
  c.free_base = true;
}

}  // namespace rfem::reading
