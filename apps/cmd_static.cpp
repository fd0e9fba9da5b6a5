// `rfem static`: the equilibrium of the case's links with the joints held (or turning steadily).
#include <fmt/core.h>

#include <optional>

#include "commands.hpp"
#include "../studies/static_study.hpp"

namespace rfem::app {

int run_static(const Common& c, const ModesOptions& o) {
  const Case cs = read_checked_case(c);
  // A target: n from a refinement of the tips' displacements and rotations (studies/accuracy.hpp).
  const AccuracySpec target = accuracy_target(cs, c);
  std::optional<AccuracyResult> acc;
  if (target.given()) {
    RefineRequest base;
    base.rate = o.rate;
    base.warn = print_warning;
    base.on_n = ladder_lines(target, c.json || c.quiet);
    acc = meet_accuracy(cs, target, reported_by_static(cs, o.rate), base);
  }
  const StaticStudy s = static_study(cs, acc ? acc->n : c.n, o.rate);
  const StaticResult& r = s.solution;
  for (const auto& w : s.warnings) print_warning(w);
  const Energies& E = s.energies;
  if (c.json) {
    nlohmann::json links = nlohmann::json::array();
    for (const LinkTip& t : s.tips)
      links.push_back({{"name", t.name}, {"n", t.n}, {"tip_displacement", {t.motion[0], t.motion[1], t.motion[2]}},
                       {"tip_rotation", {t.motion[3], t.motion[4], t.motion[5]}}});
    nlohmann::json js = {{"command", "static"}, {"case", cs.path}, {"n", s.model->n()}, {"iterations", r.iterations},
                         {"load_steps", r.load_steps}, {"residual", r.residual}, {"links", links},
                         {"elastic_energy", E.elastic}, {"gravity_energy", E.gravity}};
    js["tip_displacement"] = links.back()["tip_displacement"];  // the last link's, as with one link
    js["tip_rotation"] = links.back()["tip_rotation"];
    if (acc) js["accuracy"] = accuracy_json(*acc);
    print_json(js);
    return acc && !acc->met ? 3 : 0;
  }
  fmt::print("static equilibrium of {} with n = {} rfes: {} Newton iterations, {} load step(s), residual {:.2e} N\n",
             cs.name.empty() ? cs.path : cs.name, s.model->n(), r.iterations, r.load_steps, r.residual);
  for (const LinkTip& t : s.tips) {
    const Vec6& tip = t.motion;
    const std::string who = s.tips.size() > 1 ? fmt::format("link {} ({} rfes) ", t.name, t.n) : "";
    fmt::print("{}tip displacement [m] in {{r}}:  ux = {:.9e}  uy = {:.9e}  uz = {:.9e}\n", who, tip[0], tip[1], tip[2]);
    fmt::print("{}tip rotation [rad]:            rx = {:.9e}  ry = {:.9e}  rz = {:.9e}\n", who, tip[3], tip[4], tip[5]);
  }
  fmt::print("elastic energy {:.9e} J, gravity energy {:.9e} J\n", E.elastic, E.gravity);
  if (acc) print_accuracy(*acc);
  return acc && !acc->met ? 3 : 0;  // (a target that was not met is not success)
}

}  // namespace rfem::app
