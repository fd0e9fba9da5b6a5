#include "model.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "check.hpp"

namespace rfem {

namespace {

Mat4 translation(const Vec3& t) { return homogeneous(Mat3::Identity(), t); }

std::string what(const Model& M, bool joint, int i) {
  return joint ? "joint " + std::to_string(i + 1) + " (" + M.joints[i].name + ")"
               : "link " + std::to_string(i + 1) + " (" + M.links[i].name + ")";
}

// The rfe of link l that a mounting at `at` rides on (−1: rfe_0, rigid with {r}, or a rigid link).
int carrying_rfe(const MountedLink& l, double at) { return l.n() > 0 ? rfe_at(l.d, at) : -1; }

// Where something mounted with `on` sits: its parent node and the constant transform from that
// node's frame (`on.X` included). Needs the parent placed.
void locate(const Model& M, const Mounting& on, int& node, Mat4& X) {
  switch (on.kind) {
    case Mounting::Kind::Ground:
      node = -1;
      X = on.X;
      return;
    case Mounting::Kind::Joint:
      node = M.joint_node[on.index];
      X = on.X;
      return;
    default: {
      const MountedLink& p = M.links[on.index];
      const Vec3 point(on.at, 0.0, 0.0);
      const int k = carrying_rfe(p, on.at);
      if (k < 0) {  // rigid with {r}: on the link's own parent
        node = p.parent;
        X = p.mount * translation(point) * on.X;
      } else {  // on rfe k's frame (its last axis node), from its mass centre
        node = p.carrier[k] + 5;
        X = translation(point - p.d.rfes[k].centre) * on.X;
      }
    }
  }
}

bool placed(const Mounting& on, const std::vector<char>& joint_done, const std::vector<char>& link_done) {
  if (on.kind == Mounting::Kind::Ground) return true;
  if (on.kind == Mounting::Kind::Joint) return joint_done[on.index];
  return link_done[on.index];
}

void set_path(Model& M, int i) {
  Node& nd = M.nodes[i];
  nd.path = nd.parent >= 0 ? M.nodes[nd.parent].path : std::vector<int>{};
  nd.path.push_back(i);
}

// Places link l: {r}, the six axis nodes of each carrying rfe, rfe_0's inertia on the parent.
void place_link(Model& M, int l) {
  MountedLink& L = M.links[l];
  locate(M, L.on, L.parent, L.mount);
  L.ancestors = L.parent >= 0 ? M.nodes[L.parent].path : std::vector<int>{};
  // Axis order x1, x2, x3, φ2, φ3, φ1: D = Trans(x) RotY(φ2) RotZ(φ3) RotX(φ1) (core/rotation.hpp).
  static const int coord_of_axis[6] = {0, 1, 2, 4, 5, 3};
  static const Vec3 axis_of[6] = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ(), Vec3::UnitY(), Vec3::UnitZ(), Vec3::UnitX()};
  for (int k = 0; k < L.n(); ++k) {
    if (!L.carries(k)) continue;
    L.carrier[k] = static_cast<int>(M.nodes.size());
    for (int a = 0; a < 6; ++a) {
      Node nd;
      nd.parent = a == 0 ? L.parent : L.carrier[k] + a - 1;
      nd.motion.name = L.name + ".rfe" + std::to_string(k + 1) + ".axis" + std::to_string(a + 1);
      nd.motion.type = a < 3 ? JointType::Prismatic : JointType::Revolute;
      nd.motion.axis = axis_of[a];
      nd.motion.on.kind = Mounting::Kind::Ground;  // (placement is the node's)
      if (a == 0) {
        nd.pre = L.mount * translation(L.d.rfes[k].centre);
        nd.has_pre = true;
      }
      if (a == 5) nd.H = L.d.rfes[k].H;
      nd.coord = L.coord[k] + coord_of_axis[a];
      nd.link = l;
      nd.rfe = k;
      M.nodes.push_back(nd);
      set_path(M, static_cast<int>(M.nodes.size()) - 1);
    }
  }
  if (L.parent >= 0) {  // rfe_0 (or a rigid link) is rigid with its parent's body
    const Mat4 X = L.mount * translation(L.d.rfe0.centre);
    M.nodes[L.parent].H += X * L.d.rfe0.H * X.transpose();
  }
}

void place_joint(Model& M, int j) {
  Node nd;
  const Mounting& on = M.joints[j].on;
  locate(M, on, nd.parent, nd.pre);
  // A joint on the previous joint or the ground with no transform of its own is a plain DH link.
  nd.has_pre = on.kind == Mounting::Kind::Link || !on.X.isIdentity(0.0);
  if (!nd.has_pre) nd.pre = Mat4::Identity();
  nd.motion = M.joints[j];
  nd.H = M.joints[j].H;
  nd.coord = M.joint_index(j);
  nd.joint = j;
  M.joint_node[j] = static_cast<int>(M.nodes.size());
  M.nodes.push_back(nd);
  set_path(M, M.joint_node[j]);
}

}  // namespace

std::string name_problem(const std::string& name) {
  if (name.empty()) return "a name cannot be empty";
  if (name == "." || name == "..") return "'" + name + "' cannot be a name";
  for (unsigned char ch : name) {
    if (ch == '/') return "a name cannot hold '/' (it names a group of the results file)";
    if (ch < 0x20 || ch == 0x7f) return "a name cannot hold control characters";
  }
  return "";
}

Model make_model(std::vector<Joint> joints, std::vector<MountedLink> links, double gravity, bool free_base) {
  Model M;
  M.joints = std::move(joints);
  M.links = std::move(links);
  M.gravity = gravity;
  M.free_base = free_base;
  const int m = M.m(), nl = static_cast<int>(M.links.size());
  for (int j = 0; j < m; ++j) {
    const Joint& jt = M.joints[j];
    try {
      jt.drive.check();
      if (!jt.H.allFinite() || !(jt.H(3, 3) >= 0.0)) throw std::invalid_argument("its body's inertia must be finite, its mass not negative");
      if (!jt.axis.allFinite() || std::abs(jt.axis.norm() - 1.0) > 1e-9) throw std::invalid_argument("its axis must be a unit vector");
      for (double x : {jt.alpha, jt.a, jt.theta, jt.d}) require_finite("its DH parameters", x);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(what(M, true, j) + ": " + e.what());
    }
  }
  require_non_negative("gravity", M.gravity);
  for (int l = 0; l < nl; ++l) {  // link names are paths of results: usable and distinct
    if (const std::string why = name_problem(M.links[l].name); !why.empty())
      throw std::invalid_argument(what(M, false, l) + ": " + why);
    for (int k = 0; k < l; ++k)
      if (M.links[k].name == M.links[l].name)
        throw std::invalid_argument(what(M, false, l) + ": another link has the same name");
  }
  {  // defaults and checks of every mounting (core/mounting.hpp)
    std::vector<Mounting> jon, lon;
    std::vector<std::string> jn, ln;
    std::vector<double> len;
    for (const Joint& j : M.joints) jon.push_back(j.on), jn.push_back(j.name);
    for (const MountedLink& L : M.links) lon.push_back(L.on), ln.push_back(L.name), len.push_back(L.d.length);
    resolve_mountings(jon, lon, jn, ln, len);
    for (int j = 0; j < m; ++j) M.joints[j].on = jon[j];
    for (int l = 0; l < nl; ++l) M.links[l].on = lon[l];
  }
  // Which rfes carry something (derived fields of links given again are recomputed).
  for (MountedLink& L : M.links) {
    L.carrier.assign(L.n(), -1);
    L.carrier_sdes.clear();
  }
  auto mark = [&](const Mounting& on) {
    if (on.kind != Mounting::Kind::Link) return;
    const int k = carrying_rfe(M.links[on.index], on.at);
    if (k >= 0) M.links[on.index].carrier[k] = 0;  // (its node index comes when it is placed)
  };
  for (const Joint& j : M.joints) mark(j.on);
  for (const MountedLink& L : M.links) mark(L.on);
  // Coordinates: rfes that carry nothing, then carrying ones, then joints.
  int c = 0;
  for (int pass = 0; pass < 2; ++pass)
    for (MountedLink& L : M.links) {
      L.coord.resize(L.n());
      for (int k = 0; k < L.n(); ++k)
        if (L.carries(k) == (pass == 1)) {
          L.coord[k] = c;
          c += Model::rfe_dofs;
          M.carrying += pass;
        }
    }
  M.rfes = c / Model::rfe_dofs;
  for (MountedLink& L : M.links)
    for (int e = 0; e < L.n(); ++e)
      if (L.carries(e) || (e > 0 && L.carries(e - 1))) L.carrier_sdes.push_back(e);
  // The tree: place whatever sits on something placed, links first, until nothing is left.
  M.joint_node.assign(m, -1);
  std::vector<char> joint_done(m, 0), link_done(nl, 0);
  for (bool progress = true; progress;) {
    progress = false;
    for (int l = 0; l < nl; ++l)
      if (!link_done[l] && placed(M.links[l].on, joint_done, link_done)) {
        place_link(M, l);
        link_done[l] = progress = true;
      }
    for (int j = 0; j < m; ++j)
      if (!joint_done[j] && placed(M.joints[j].on, joint_done, link_done)) {
        place_joint(M, j);
        joint_done[j] = progress = true;
      }
  }
  // (resolve_mountings refused cycles: everything is placed)
  return M;
}

Model make_model(std::vector<Joint> joints, const Mat4& mount, Discretisation link, double gravity) {
  std::vector<MountedLink> links;
  if (link.n() > 0 || link.length > 0) {
    MountedLink L;
    L.name = "link";
    L.d = std::move(link);
    L.on.X = mount;
    links.push_back(std::move(L));
  }
  return make_model(std::move(joints), std::move(links), gravity);
}

Model rigidify(const Model& model) {
  std::vector<MountedLink> links;
  for (const MountedLink& L : model.links) {
    MountedLink r;
    r.name = L.name;
    r.d = L.d.rigid();
    r.on = L.on;
    links.push_back(std::move(r));
  }
  return make_model(model.joints, std::move(links), model.gravity, model.free_base);
}

}  // namespace rfem
