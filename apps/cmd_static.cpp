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
  const Vec6 tip = tip_motion(model, r.q);
  const Energies E = energies(model, r.q, VecX::Zero(model.dof()));
  if (c.json) {
    print_json({{"command", "static"}, {"case", cs.path}, {"n", model.n()}, {"iterations", r.iterations},
                {"load_steps", r.load_steps}, {"residual", r.residual},
                {"tip_displacement", {tip[0], tip[1], tip[2]}}, {"tip_rotation", {tip[3], tip[4], tip[5]}},
                {"elastic_energy", E.elastic}, {"gravity_energy", E.gravity}});
    return 0;
  }
  fmt::print("static equilibrium of {} with n = {} rfes: {} Newton iterations, {} load step(s), residual {:.2e} N\n",
             cs.name.empty() ? cs.path : cs.name, model.n(), r.iterations, r.load_steps, r.residual);
  fmt::print("tip displacement [m] in {{r}}:  ux = {:.9e}  uy = {:.9e}  uz = {:.9e}\n", tip[0], tip[1], tip[2]);
  fmt::print("tip rotation [rad]:            rx = {:.9e}  ry = {:.9e}  rz = {:.9e}\n", tip[3], tip[4], tip[5]);
  fmt::print("elastic energy {:.9e} J, gravity energy {:.9e} J\n", E.elastic, E.gravity);
  return 0;
}

}  // namespace rfem::app
