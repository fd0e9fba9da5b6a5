#include "mounting.hpp"

#include <algorithm>

#include "check.hpp"

namespace rfem {

void resolve_mountings(std::vector<Mounting>& joints, std::vector<Mounting>& links,
                       const std::vector<std::string>& joint_names, const std::vector<std::string>& link_names,
                       const std::vector<double>& link_lengths) {
  const int m = static_cast<int>(joints.size()), nl = static_cast<int>(links.size());
  RFEM_CHECK_ARGUMENT_SIZE(joint_names.size(), m, "joint_names");
  RFEM_CHECK_ARGUMENT_SIZE(link_names.size(), nl, "link_names");
  RFEM_CHECK_ARGUMENT_SIZE(link_lengths.size(), nl, "link_lengths");
  auto who = [&](bool joint, int i) {
    return joint ? "joint " + std::to_string(i + 1) + " (" + joint_names[i] + ")"
                 : "link " + std::to_string(i + 1) + " (" + link_names[i] + ")";
  };
  // Joints first: a link's default follows the joints' resolved chain.
  for (int j = 0; j < m; ++j)
    if (joints[j].kind == Mounting::Kind::Chain) {
      joints[j].kind = j > 0 ? Mounting::Kind::Joint : Mounting::Kind::Ground;
      joints[j].index = j - 1;
    }
  auto on_a_link = [&](int j) {  // whether joint j's mountings lead through a link (bounded: cycles)
    for (int steps = 0; j >= 0 && steps <= m; ++steps) {
      const Mounting& on = joints[j];
      if (on.kind == Mounting::Kind::Link) return true;
      j = on.kind == Mounting::Kind::Joint ? on.index : -1;
      if (j >= m) return false;
    }
    return false;
  };
  for (int l = 0; l < nl; ++l)
    if (links[l].kind == Mounting::Kind::Chain) {
      int j = m - 1;
      while (j >= 0 && on_a_link(j)) --j;
      links[l].kind = j >= 0 ? Mounting::Kind::Joint : Mounting::Kind::Ground;
      links[l].index = j;
    }
  auto check = [&](bool joint, int i, Mounting& on) {
    if (on.kind == Mounting::Kind::Joint && (on.index < 0 || on.index >= m))
      throw MountingError(joint, i, who(joint, i) + " is mounted on joint " + std::to_string(on.index + 1) + ", which does not exist");
    if (on.kind != Mounting::Kind::Link) return;
    if (on.index < 0 || on.index >= nl)
      throw MountingError(joint, i, who(joint, i) + " is mounted on link " + std::to_string(on.index + 1) + ", which does not exist");
    const double L = link_lengths[on.index];
    if (on.at < 0) on.at = L;
    if (!(on.at <= L * (1 + 1e-12)))
      throw MountingError(joint, i, who(joint, i) + " is mounted at " + std::to_string(on.at) + " m on " + who(false, on.index) +
                                        ", which is " + std::to_string(L) + " m long");
    on.at = std::min(on.at, L);
  };
  for (int j = 0; j < m; ++j) check(true, j, joints[j]);
  for (int l = 0; l < nl; ++l) check(false, l, links[l]);
  // No cycles: from every joint and link, the parents lead to the ground.
  struct Entity {
    bool joint = false;
    int index = -1;  // −1: the ground
  };
  auto name_of = [&](const Entity& e) { return e.joint ? joint_names[e.index] : link_names[e.index]; };
  auto parent = [&](const Entity& e) {
    const Mounting& on = e.joint ? joints[e.index] : links[e.index];
    if (on.kind == Mounting::Kind::Ground) return Entity{};
    return Entity{on.kind == Mounting::Kind::Joint, on.index};
  };
  for (int start = 0; start < m + nl; ++start) {
    const Entity first = start < m ? Entity{true, start} : Entity{false, start - m};
    std::string chain = name_of(first);
    Entity e = first;
    for (int steps = 0; steps <= m + nl; ++steps) {
      e = parent(e);
      if (e.index < 0) break;
      chain += " -> " + name_of(e);
      if (e.joint == first.joint && e.index == first.index)
        throw MountingError(first.joint, first.index, "the mountings form a cycle (" + chain + ")");
    }
  }
}

}  // namespace rfem
