#include <fmt/core.h>

#include "apps/commands.hpp"
#include "assembly/assemble.hpp"
#include "solvers/statics.hpp"

namespace rfem::app {

int run_static(const Common& c, const ModesOptions& o) {
  const Case cs = read_checked_case(c);
  const Model model = build_model(cs, c.n);
  if (model.n() == 0) throw CaseError(cs.path + ": link: static analysis needs a flexible link");
  VecX qb, vb;
  joint_state(cs, o, qb, vb);
  const StaticResult r = solve_static(model, qb, vb, cs.loads);
  const Energies E = energies(model, r.q, VecX::Zero(model.dof()));
  const int nl = static_cast<int>(model.links.size());
  if (c.json) {
    nlohmann::json links = nlohmann::json::array();
    for (int l = 0; l < nl; ++l) {
      const Vec6 tip = tip_motion(model, l, r.q);
      links.push_back({{"name", model.links[l].name}, {"n", model.links[l].n()},
                       {"tip_displacement", {tip[0], tip[1], tip[2]}}, {"tip_rotation", {tip[3], tip[4], tip[5]}}});
    }
    nlohmann::json js = {{"command", "static"}, {"case", cs.path}, {"n", model.n()}, {"iterations", r.iterations},
                         {"load_steps", r.load_steps}, {"residual", r.residual}, {"links", links},
                         {"elastic_energy", E.elastic}, {"gravity_energy", E.gravity}};
    js["tip_displacement"] = links.back()["tip_displacement"];  // the last link's, as with one link
    js["tip_rotation"] = links.back()["tip_rotation"];
    print_json(js);
    return 0;
  }
  fmt::print("static equilibrium of {} with n = {} rfes: {} Newton iterations, {} load step(s), residual {:.2e} N\n",
             cs.name.empty() ? cs.path : cs.name, model.n(), r.iterations, r.load_steps, r.residual);
  for (int l = 0; l < nl; ++l) {
    const Vec6 tip = tip_motion(model, l, r.q);
    const std::string who = nl > 1 ? fmt::format("link {} ({} rfes) ", model.links[l].name, model.links[l].n()) : "";
    fmt::print("{}tip displacement [m] in {{r}}:  ux = {:.9e}  uy = {:.9e}  uz = {:.9e}\n", who, tip[0], tip[1], tip[2]);
    fmt::print("{}tip rotation [rad]:            rx = {:.9e}  ry = {:.9e}  rz = {:.9e}\n", who, tip[3], tip[4], tip[5]);
  }
  fmt::print("elastic energy {:.9e} J, gravity energy {:.9e} J\n", E.elastic, E.gravity);
  return 0;
}

}  // namespace rfem::app
