#include "show.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <functional>

#include "../simulation/inputs.hpp"
#include "../solvers/equations.hpp"
#include "../solvers/modes.hpp"
#include "../solvers/reduction.hpp"

namespace rfem {

namespace {

std::string input_text(const InputSpec& in) {
  if (in.none_given) return "none given: free, under zero torque (force input)";
  std::string s = to_string(in.kind);
  if (in.kind == InputKind::Pd && in.reference)
    s += " on " + to_string(in.reference->kind) + (in.feedforward == Feedforward::Rigid ? " + rigid computed torque" : "");
  return s + (in.prescribed() ? " (motion: kinematic input)" : in.kind == InputKind::Pd ? " (feedback: force input)" : " (force input)");
}

std::string axis_text(const Joint& j) {
  const Vec3& u = j.axis;
  for (int i = 0; i < 3; ++i)
    if (std::abs(std::abs(u[i]) - 1.0) < 1e-12) return std::string(u[i] < 0 ? "-" : "") + "xyz"[i];
  return fmt::format("({:.3g}, {:.3g}, {:.3g})", u[0], u[1], u[2]);
}

// The runs of consecutive indices, "q[0…41], q[90…95]".
std::string ranges(std::vector<int> idx) {
  std::sort(idx.begin(), idx.end());
  std::string out;
  for (size_t i = 0; i < idx.size();) {
    size_t j = i;
    while (j + 1 < idx.size() && idx[j + 1] == idx[j] + 1) ++j;
    out += (out.empty() ? "" : ", ") + (j == i ? fmt::format("q[{}]", idx[i]) : fmt::format("q[{}…{}]", idx[i], idx[j]));
    i = j + 1;
  }
  return out;
}

}  // namespace

ModelSummary show_model(const Case& cs, int n) {
  const auto mp = model_of(cs, n);
  const Model& M = *mp;
  const std::vector<std::vector<int>> parts = link_parts(cs, n);
  ModelSummary s;
  s.name = cs.name.empty() ? cs.path : cs.name;
  s.n = M.n();
  s.m = M.m();
  s.dof = M.dof();
  s.unknowns = M.flexible_dofs();
  // A reduced link's unknowns are its rfes' displacements, its modes and their derivatives: the
  // reduction says how many (its modes taken where the equations take them).
  if (const auto red = Reduction::of(M, initial_joint_values(M, joint_inputs(cs)))) s.unknowns = red->rfe();
  for (const InputSpec& in : cs.inputs) s.unknowns += in.prescribed() ? 0 : 1;
  // Children of every entity (a joint j is 2j, a link l is 2l + 1; the ground is −1).
  auto key = [](bool joint, int i) { return joint ? 2 * i : 2 * i + 1; };
  std::vector<std::vector<int>> children(2 * (M.m() + M.links.size()) + 1);
  auto parent_key = [&](const Mounting& on) {
    return on.kind == Mounting::Kind::Joint ? key(true, on.index) : on.kind == Mounting::Kind::Link ? key(false, on.index) : -1;
  };
  std::vector<int> roots;
  auto attach = [&](const Mounting& on, int k) {
    const int p = parent_key(on);
    (p < 0 ? roots : children[p]).push_back(k);
  };
  for (int j = 0; j < M.m(); ++j) attach(M.joints[j].on, key(true, j));
  for (size_t l = 0; l < M.links.size(); ++l) attach(M.links[l].on, key(false, static_cast<int>(l)));
  auto name_of = [&](const Mounting& on) {
    return on.kind == Mounting::Kind::Joint ? M.joints[on.index].name
           : on.kind == Mounting::Kind::Link ? M.links[on.index].name : std::string("ground");
  };
  auto where = [&](const Mounting& on) {
    if (on.kind != Mounting::Kind::Link) return std::string();
    const double L = M.links[on.index].d.length;
    return on.at >= L * (1 - 1e-12) ? fmt::format("tip ({:g} m)", L) : fmt::format("at {:g} m", on.at);
  };
  std::function<void(int, int)> visit = [&](int k, int depth) {
    TreeEntry e;
    e.depth = depth;
    if (k % 2 == 0) {
      const int j = k / 2;
      const Joint& jt = M.joints[j];
      e.kind = "joint";
      e.name = jt.name;
      e.parent = name_of(jt.on);
      e.where = where(jt.on);
      e.mass = jt.mass();
      e.detail = fmt::format("{} about {}{}", jt.type == JointType::Revolute ? "revolute" : "prismatic (along",
                             axis_text(jt), jt.type == JointType::Revolute ? "" : ")");
      if (j < static_cast<int>(cs.inputs.size())) e.detail += "; input " + input_text(cs.inputs[j]);
      e.coordinates = ranges({M.joint_index(j)});
      s.entries.push_back(e);
    } else {
      const int l = k / 2;
      const MountedLink& L = M.links[l];
      e.kind = "link";
      e.name = L.name;
      e.parent = name_of(L.on);
      e.where = where(L.on);
      e.rfes = L.n();
      e.length = L.d.length;
      const LinkCase& lc = cs.links[l];
      for (const Segment& sg : lc.link.segments) e.mass += sg.material.rho * sg.section.A * sg.length;
      e.detail = fmt::format("{} segment{}", lc.link.segments.size(), lc.link.segments.size() > 1 ? "s" : "");
      for (size_t g = 0; g < lc.link.segments.size(); ++g) {
        const Segment& sg = lc.link.segments[g];
        e.detail += fmt::format(", {:g} m {}/{} in {} part{}", sg.length, sg.material.name, sg.section.name, parts[l][g],
                                parts[l][g] > 1 ? "s" : "");
      }
      if (L.d.modes > 0)
        e.detail += fmt::format("; reduced: {} mode{} of its rotations{} and its {} displacements", L.d.modes, L.d.modes > 1 ? "s" : "",
                                L.d.derivatives > 0 ? fmt::format(", at most {} modal derivatives", L.d.derivatives * (L.d.derivatives + 1) / 2) : "",
                                kModalFirst * L.n());
      std::vector<int> idx;  // its rfes' coordinates (an rfe that carries something sits in the border)
      for (int r = 0; r < L.n(); ++r)
        for (int a = 0; a < Model::rfe_dofs; ++a) idx.push_back(M.rfe_index(l, r) + a);
      e.coordinates = ranges(idx);
      s.entries.push_back(e);
      for (size_t p = 0; p < L.d.payloads.size(); ++p) {
        const Payload& pl = L.d.payloads[p];
        TreeEntry pe;
        pe.kind = "payload";
        pe.name = fmt::format("{}.payload{}", L.name, p + 1);
        pe.depth = depth + 1;
        pe.parent = L.name;
        pe.where = pl.at >= L.d.length * (1 - 1e-12) ? fmt::format("tip ({:g} m)", L.d.length) : fmt::format("at {:g} m", pl.at);
        pe.mass = pl.H(3, 3);
        s.entries.push_back(pe);
      }
    }
    for (int c : children[k]) visit(c, depth + 1);
  };
  for (int r : roots) visit(r, 0);
  for (const TreeEntry& e : s.entries) s.mass += e.mass;
  s.urdf = cs.urdf;
  for (const BodyFrame& f : cs.frames) {
    TreeEntry e;
    e.kind = "frame";
    e.name = f.name;
    e.parent = f.joint < 0 ? std::string("ground") : M.joints[f.joint].name;
    const Vec3 x = f.X.topRightCorner<3, 1>();
    if (x != Vec3::Zero()) e.where = fmt::format("at ({:g}, {:g}, {:g}) m", x[0], x[1], x[2]);
    if (f.X.topLeftCorner<3, 3>() != Mat3::Identity()) e.where += std::string(e.where.empty() ? "" : ", ") + "turned";
    s.frames.push_back(e);
  }
  return s;
}

std::string format_summary(const ModelSummary& s) {
  std::string out = fmt::format("{}: {} joint{}, {} rfe{} in all; {} coordinates, {} of them unknown under the inputs; "
                                "{:.6g} kg in all\n",
                                s.name, s.m, s.m == 1 ? "" : "s", s.n, s.n == 1 ? "" : "s", s.dof, s.unknowns, s.mass);
  if (!s.urdf.empty()) {
    out += "base from " + s.urdf + ", its links on the bodies:";
    for (const TreeEntry& f : s.frames)
      out += fmt::format(" {} on {}{}{}", f.name, f.parent, f.where.empty() ? "" : " " + f.where, &f == &s.frames.back() ? "" : ";");
    out += "\n";
  }
  for (const TreeEntry& e : s.entries) {
    const std::string on = e.parent == "ground" ? "on the ground" : "on " + e.parent + (e.where.empty() ? "" : ", " + e.where);
    std::string what;
    if (e.kind == "joint") what = fmt::format("{}; body {:.6g} kg", e.detail, e.mass);
    else if (e.kind == "link") what = fmt::format("{:g} m, {} rfes, {:.6g} kg: {}", e.length, e.rfes, e.mass, e.detail);
    else what = fmt::format("{:.6g} kg", e.mass);
    out += fmt::format("{:{}}{} {} — {}: {}{}\n", "", 2 * e.depth, e.kind, e.name, on, what,
                       e.coordinates.empty() ? "" : "; " + e.coordinates);
  }
  return out;
}

}  // namespace rfem
