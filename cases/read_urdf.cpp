// A rigid base from a URDF file ([base] urdf = "arm.urdf"): one joint of the case per movable URDF
// joint, found by walking the tree from its root link. A URDF joint's child link frame is
//   parent link frame · origin(xyz, rpy) · Rot(axis, q)   (or Trans(axis q)),
// which is a joint of core/base_chain.hpp with zero DH parameters, its axis, and `origin` as the
// constant transform of its mounting. Fixed joints are not joints of the model: the child link is
// welded to the body it hangs on (its inertia added there, its frame kept as a named frame). The
// root link is the ground. Every URDF link's name is a frame a flexible link or a case joint may be
// mounted on (`parent = "forearm"`).
#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>

#include "case_reading_impl.hpp"
#include "../core/link.hpp"
#include "../core/rotation.hpp"

namespace rfem::reading {

namespace {

// urdfdom reports through console_bridge, a process-wide logger: while one file is parsed its
// messages are caught here (the first error becomes the one-line message), then the previous
// handler is restored. The lock keeps two readers in one process apart.
class Catch : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && first.empty()) first = text.substr(0, text.find('\n'));
  }
  std::string first;
};

urdf::ModelInterfaceSharedPtr parse(const std::string& text, std::string& error) {
  static std::mutex lock;
  const std::lock_guard<std::mutex> hold(lock);
  Catch c;
  console_bridge::useOutputHandler(&c);
  urdf::ModelInterfaceSharedPtr m;
  try {
    m = urdf::parseURDF(text);
  } catch (const std::exception& e) {
    c.first = e.what();
  }
  console_bridge::restorePreviousOutputHandler();
  error = c.first.empty() ? "not a URDF robot description" : c.first;
  return m;
}

// `count` finite numbers separated by white space, and nothing else.
bool numbers(const char* text, int count) {
  const char* p = text;
  const char* end = text + std::char_traits<char>::length(text);
  for (int i = 0; i < count; ++i) {
    while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
    if (p < end && *p == '+') ++p;  // (from_chars takes no '+')
    double v = 0.0;
    const auto [next, ec] = std::from_chars(p, end, v);
    if (ec != std::errc() || next == p || !std::isfinite(v)) return false;
    p = next;
    if (p < end && !std::isspace(static_cast<unsigned char>(*p))) return false;  // "3.0x"
  }
  while (p < end && std::isspace(static_cast<unsigned char>(*p))) ++p;
  return p == end;
}

// urdfdom reads numbers leniently ("three" as 0, "3.0 4.0" as 3.0, "nan" as NaN): every number rfem
// takes from the file is read again here from the XML, strictly. `fail` gets "LINE: link 'x': …".
void check_numbers(const std::string& text, const std::function<void(const std::string&)>& fail) {
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  const TiXmlElement* robot = doc.Error() ? nullptr : doc.FirstChildElement("robot");
  if (!robot) return;  // urdfdom says what is wrong
  auto check = [&](const TiXmlElement* parent, const char* tag, std::initializer_list<const char*> attrs, int count,
                   const std::string& who) {
    if (!parent) return;
    for (const TiXmlElement* e = parent->FirstChildElement(tag); e; e = e->NextSiblingElement(tag))
      for (const char* a : attrs)
        if (const char* v = e->Attribute(a); v && !numbers(v, count))
          fail(std::to_string(e->Row()) + ": " + who + ": <" + tag + " " + a + "=\"" + v + "\">: " +
               (count == 1 ? "must be a finite number" : "must be " + std::to_string(count) + " finite numbers"));
  };
  for (const TiXmlElement* l = robot->FirstChildElement("link"); l; l = l->NextSiblingElement("link")) {
    const std::string who = "link '" + std::string(l->Attribute("name") ? l->Attribute("name") : "") + "'";
    const TiXmlElement* in = l->FirstChildElement("inertial");
    check(in, "origin", {"xyz", "rpy"}, 3, who);
    check(in, "mass", {"value"}, 1, who);
    check(in, "inertia", {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"}, 1, who);
  }
  for (const TiXmlElement* j = robot->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint")) {
    const std::string who = "joint '" + std::string(j->Attribute("name") ? j->Attribute("name") : "") + "'";
    check(j, "origin", {"xyz", "rpy"}, 3, who);
    check(j, "axis", {"xyz"}, 3, who);
    check(j, "limit", {"lower", "upper", "effort", "velocity"}, 1, who);
    check(j, "dynamics", {"damping", "friction"}, 1, who);
  }
}

Mat4 pose(const urdf::Pose& p) {
  double x, y, z, w;
  p.rotation.getQuaternion(x, y, z, w);
  const Eigen::Quaterniond q(w, x, y, z);
  return homogeneous(q.normalized().toRotationMatrix(), Vec3(p.position.x, p.position.y, p.position.z));
}

}  // namespace

void read_urdf_base(const Reader& r, const toml::table& bt, const std::string& case_dir, Case& c,
                    std::vector<ParentRef>& parents) {
  const toml::node* un = bt.get("urdf");
  const std::string given = r.string(bt, "base", "urdf");
  const std::string file = (given.empty() || given[0] == '/') ? given : case_dir + given;
  auto fail = [&](const std::string& what) { r.fail(un, "base.urdf", given + ": " + what); };
  std::ifstream in(file);
  if (!in) r.fail(un, "base.urdf", "cannot open '" + file + "'");
  std::stringstream buf;
  buf << in.rdbuf();
  check_numbers(buf.str(), [&](const std::string& what) { r.fail(un, "base.urdf", given + ":" + what); });
  std::string error;
  const urdf::ModelInterfaceSharedPtr model = parse(buf.str(), error);
  if (!model) fail(error);
  if (!model->getRoot()) fail("no root link");
  {  // urdfdom keeps the last of a link's parent joints and drops the others without a word
    std::map<std::string, std::string> parent_of;
    for (const auto& [name, j] : model->joints_)
      if (const auto [it, first] = parent_of.emplace(j->child_link_name, name); !first)
        fail("link '" + j->child_link_name + "' has two parent joints, '" + it->second + "' and '" + name +
             "' (a URDF is a tree: each link hangs on one joint)");
  }
  c.urdf = file;

  // Per joint of the URDF: value, rate, input, drive ([base.joints.NAME]).
  const toml::table* given_joints = nullptr;
  if (const toml::node* jn = bt.get("joints")) {
    if (!jn->is_table()) r.fail(jn, "base.joints", "must be a table of URDF joint names, e.g. [base.joints.shoulder]");
    given_joints = jn->as_table();
    for (const auto& [k, v] : *given_joints) {
      const std::string name(k.str());
      const urdf::JointConstSharedPtr uj = model->getJoint(name);
      if (!uj) {
        std::string list;
        for (const auto& [jname, j] : model->joints_)
          if (j->type != urdf::Joint::FIXED) list += (list.empty() ? "" : ", ") + jname;
        r.fail(&v, "base.joints." + name, "no movable joint named '" + name + "' in " + given + " (" + list + ")");
      }
      if (uj->type == urdf::Joint::FIXED) r.fail(&v, "base.joints." + name, "is a fixed joint in " + given + ": it has no coordinate");
      if (!v.is_table()) r.fail(&v, "base.joints." + name, "must be a table {value, rate, input, drive}");
    }
  }

  std::vector<Joint> joints;
  std::vector<ParentRef> refs;
  std::vector<double> values, rates;
  std::vector<InputSpec> inputs;
  std::vector<std::string> free_joints;  // given no input
  struct Where {
    int joint = -1;  // the body it is welded to: a joint's, −1 the ground
    Mat4 X = Mat4::Identity();
  };
  std::map<std::string, Where> at;  // URDF link → body and frame
  auto inertial = [&](const urdf::LinkConstSharedPtr& l) -> Mat4 {
    if (!l->inertial) return Mat4::Zero();
    const urdf::Inertial& u = *l->inertial;
    Mat3 I;
    I << u.ixx, u.ixy, u.ixz, u.ixy, u.iyy, u.iyz, u.ixz, u.iyz, u.izz;
    const std::string what = "link '" + l->name + "': inertial ";
    if (!(u.mass >= 0.0) || !std::isfinite(u.mass) || u.mass > 1e12) fail(what + "mass must lie within 0 to 1e12 kg");
    if (!I.allFinite()) fail(what + "inertia must be finite");
    const Eigen::Vector3d e = I.selfadjointView<Eigen::Upper>().eigenvalues();
    const double tol = 1e-12 * std::max(1.0, e.cwiseAbs().maxCoeff());
    if (e.minCoeff() < -tol || e[0] + e[1] < e[2] - tol)
      fail(what + "inertia is not that of a body (principal moments " + Reader::fmt(e[0]) + ", " + Reader::fmt(e[1]) + ", " +
           Reader::fmt(e[2]) + ": each must be ≥ 0 and at most the sum of the other two)");
    const Mat4 O = pose(u.origin);
    const Mat3 R = O.topLeftCorner<3, 3>();
    return pseudo_inertia(u.mass, O.topRightCorner<3, 1>(), R * I * R.transpose());
  };
  std::function<void(const urdf::LinkConstSharedPtr&)> walk = [&](const urdf::LinkConstSharedPtr& link) {
    std::vector<urdf::JointSharedPtr> children = link->child_joints;  // in name order: the file's order is not kept by urdfdom
    std::sort(children.begin(), children.end(), [](const auto& a, const auto& b) { return a->name < b->name; });
    for (const urdf::JointSharedPtr& uj : children) {
      const urdf::LinkConstSharedPtr child = model->getLink(uj->child_link_name);
      if (!child) fail("joint '" + uj->name + "': no link named '" + uj->child_link_name + "'");
      const Where parent = at.at(link->name);
      const Mat4 T = parent.X * pose(uj->parent_to_joint_origin_transform);
      if (!T.allFinite()) fail("joint '" + uj->name + "': origin must be finite");
      if (uj->mimic) fail("joint '" + uj->name + "': mimic joints are not supported (each joint has its own coordinate)");
      if (uj->type == urdf::Joint::FIXED) {
        at[child->name] = {parent.joint, T};
        if (parent.joint >= 0) joints[parent.joint].H += T * inertial(child) * T.transpose();
        else inertial(child);  // checked; on the ground it does not move
        walk(child);
        continue;
      }
      Joint j;
      j.name = uj->name;
      if (const std::string why = name_problem(j.name); !why.empty()) fail("joint '" + uj->name + "': " + why);
      if (uj->type == urdf::Joint::REVOLUTE || uj->type == urdf::Joint::CONTINUOUS) j.type = JointType::Revolute;
      else if (uj->type == urdf::Joint::PRISMATIC) j.type = JointType::Prismatic;
      else
        fail("joint '" + uj->name + "': " + (uj->type == urdf::Joint::FLOATING ? "floating" : uj->type == urdf::Joint::PLANAR ? "planar" : "unknown") +
             " joints are not supported (revolute, continuous, prismatic, fixed; a floating base is [base] kind = \"free\" in TOML)");
      j.axis = Vec3(uj->axis.x, uj->axis.y, uj->axis.z);
      if (!(j.axis.norm() > 0.0) || !j.axis.allFinite()) fail("joint '" + uj->name + "': axis must be a non-zero direction");
      j.axis.normalize();
      j.H = inertial(child);
      if (uj->limits) {  // (urdfdom gives 0 for what a <limit> leaves out: not a limit)
        const urdf::JointLimits& l = *uj->limits;
        if (uj->type != urdf::Joint::CONTINUOUS && l.lower < l.upper) j.limits.lower = l.lower, j.limits.upper = l.upper;
        if (l.effort > 0) j.limits.effort = l.effort;
        if (l.velocity > 0) j.limits.velocity = l.velocity;
      }
      if (uj->dynamics) {
        j.drive.damping = uj->dynamics->damping;
        j.drive.friction = uj->dynamics->friction;
        if (!(j.drive.damping >= 0.0) || !(j.drive.friction >= 0.0) || !std::isfinite(j.drive.damping + j.drive.friction))
          fail("joint '" + uj->name + "': dynamics damping and friction must be finite and not negative");
      }
      double value = 0.0, rate = 0.0;
      InputSpec input;
      {
        std::ostringstream where;
        where << r.file() << ":" << bt.source().begin.line << ": base.joints." << j.name;
        input.where = where.str();
      }
      if (given_joints && given_joints->get(j.name)) {
        const toml::table& t = *given_joints->get(j.name)->as_table();
        const std::string p = "base.joints." + j.name;
        r.check_keys(t, p, {"value", "rate", "input", "drive"});
        value = j.type == JointType::Revolute ? r.angle(t, p, "value", 0.0) : r.number(t, p, "value", 0.0);
        rate = r.number(t, p, "rate", 0.0);
        if (const toml::node* dn = t.get("drive")) {
          if (!dn->is_table()) r.fail(dn, p + ".drive", "must be a table {inertia = …, damping = …, friction = …}");
          j.drive = read_drive(r, *dn->as_table(), p + ".drive");
        }
        if (const toml::node* inn = t.get("input")) {
          if (!inn->is_table()) r.fail(inn, p + ".input", "must be a table {kind = …}");
          input = read_input(r, *inn->as_table(), p + ".input", case_dir);
        }
        if (uj->limits && uj->type != urdf::Joint::CONTINUOUS && uj->limits->lower < uj->limits->upper &&
            (value < uj->limits->lower || value > uj->limits->upper))
          r.warn(t.get("value"), p + ".value", "lies outside the joint's limits in " + given + ", " + Reader::fmt(uj->limits->lower) +
                                                   " to " + Reader::fmt(uj->limits->upper));
      }
      if (!given_joints || !given_joints->get(j.name) || !given_joints->get(j.name)->as_table()->get("input")) {
        input.none_given = true;
        free_joints.push_back(j.name);
      }
      ParentRef pr;
      pr.path = "base.urdf";
      pr.node = un;
      pr.name = parent.joint >= 0 ? joints[parent.joint].name : "ground";
      pr.X = T;
      at[child->name] = {static_cast<int>(joints.size()), Mat4::Identity()};
      joints.push_back(j);
      refs.push_back(pr);
      values.push_back(value);
      rates.push_back(rate);
      inputs.push_back(input);
      walk(child);
    }
  };
  at[model->getRoot()->name] = {};
  walk(model->getRoot());
  if (joints.empty()) fail("no movable joint (revolute, continuous or prismatic)");
  if (!free_joints.empty()) {  // the URDF brings joints the case may not have thought of: say what they do
    std::string list;
    for (const std::string& n : free_joints) list += (list.empty() ? "'" : ", '") + n + "'";
    const bool one = free_joints.size() == 1;
    r.warn(given_joints ? bt.get("joints") : un, "base.joints",
           "URDF joint" + std::string(one ? " " : "s ") + list + (one ? " has" : " have") +
               " no input: free, under zero torque (write [base.joints." + free_joints[0] +
               "] input = { kind = \"torque\", value = 0.0 } to keep " + (one ? "it" : "each") + " so, or another input)");
  }

  // The URDF's joints ahead of the case's [[joints]] (those may sit on URDF links by name).
  const long m0 = c.joint_values.size(), mu = static_cast<long>(joints.size());
  VecX v(mu + m0), w(mu + m0);
  v << Eigen::Map<const VecX>(values.data(), mu), c.joint_values;
  w << Eigen::Map<const VecX>(rates.data(), mu), c.joint_rates;
  c.joint_values = v;
  c.joint_rates = w;
  c.joints.insert(c.joints.begin(), joints.begin(), joints.end());
  c.inputs.insert(c.inputs.begin(), inputs.begin(), inputs.end());
  parents.insert(parents.begin(), refs.begin(), refs.end());
  for (const auto& [name, where] : at) c.frames.push_back({name, where.joint, where.X});
}

void refuse_joints_table(const Reader& r, const toml::node& jn, const toml::table& bt, const std::string& case_dir) {
  Case scratch;  // the URDF's joints, in the case's order (its warnings do not matter: this fails)
  std::vector<ParentRef> parents;
  read_urdf_base(r, bt, case_dir, scratch, parents);
  std::string names, hint;
  for (const Joint& j : scratch.joints) names += (names.empty() ? "" : ", ") + j.name;
  // The first path given below `joints` (joints.1.input.kp): the same setting of that URDF joint.
  std::string rest;
  const toml::node* n = &jn;
  std::string first;
  for (bool top = true; n && n->is_table() && !n->as_table()->empty(); top = false) {
    const auto it = n->as_table()->begin();  // (its pair lives in the iterator)
    (top ? first : rest) += (top || rest.empty() ? "" : ".") + std::string(it->first.str());
    n = &it->second;
  }
  char* end = nullptr;
  const long i = first.empty() ? -1 : std::strtol(first.c_str(), &end, 10);
  if (end && *end == '\0' && i >= 0 && i < static_cast<long>(scratch.joints.size()))
    hint = " (joints." + first + (rest.empty() ? "" : "." + rest) + " is base.joints." + scratch.joints[i].name +
           (rest.empty() ? "" : "." + rest) + ")";
  r.fail(&jn, "joints", "this case's joints come from its URDF (" + names + "): each one's value, rate, input and drive are in " +
                            "[base.joints.NAME]" + hint + "; [[joints]] adds joints of the case's own");
}

}  // namespace rfem::reading
