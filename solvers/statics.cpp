#include "solvers/statics.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "assembly/assemble.hpp"
#include "core/kinematics.hpp"
#include "core/rotation.hpp"
#include "solvers/cholmod_solver.hpp"

namespace rfem {

Vec6 tip_generalised_force(const Model& model, const Vec6& qn, const TipLoads& loads) {
  DeformationTransform d;
  deformation_transform(qn, d);
  Vec6 Q;
  Q.head<3>() = loads.force;
  // Angular velocity of R = Ry Rz Rx in {r}: ω = Ry Rz e1 φ̇1 + e2 φ̇2 + Ry e3 φ̇3.
  const Mat3 Ry = rot_y(qn[4]), Ryz = Ry * rot_z(qn[5]);
  const Vec3 axes[3] = {Ryz.col(0), Vec3::UnitY(), Ry.col(2)};
  for (int a = 0; a < 3; ++a)
    Q[3 + a] = loads.force.dot(d.dR[a] * model.link.tip_eta) + loads.moment.dot(axes[a]);
  return Q;
}

Vec6 tip_motion(const Model& model, const VecX& q) {
  const int n = model.n();
  Vec6 out = Vec6::Zero();
  if (n == 0) return out;
  const Vec6 qn = q.segment<6>(model.rfe_index(n - 1));
  DeformationTransform d;
  deformation_transform(qn, d);
  const Vec3& eta = model.link.tip_eta;
  out.head<3>() = qn.head<3>() + d.D.topLeftCorner<3, 3>() * eta - eta;
  out.tail<3>() = qn.tail<3>();
  return out;
}

Vec3 tip_position(const Model& model, const VecX& q) {
  const int m = model.m(), n = model.n();
  BaseKinematics bk;
  const VecX z = VecX::Zero(m);
  base_kinematics(model, model.joint_coords(q), z, z, bk);
  Vec3 local = Vec3(model.link.length, 0.0, 0.0);  // the rigid manipulator: the link's end, rigid with {r}
  if (n > 0) {
    const Vec6 qn = q.segment<6>(model.rfe_index(n - 1));
    DeformationTransform d;
    deformation_transform(qn, d, false);
    local = model.link.rfes.back().centre + qn.head<3>() + d.D.topLeftCorner<3, 3>() * model.link.tip_eta;
  }
  return bk.B0.topLeftCorner<3, 3>() * local + bk.B0.topRightCorner<3, 1>();
}

namespace {

// Residual of the flexible rows at load factor lam: internal + gravity + centrifugal − tip loads.
VecX residual(const Model& model, const VecX& q, const VecX& v, const TipLoads& loads, double lam) {
  const int n = model.n();
  VecX F;
  const VecX a = VecX::Zero(model.dof());
  ForceTerms terms;
  generalised_forces(model, q, v, a, terms, F);
  // Gravity and centrifugal forces are loads here: scale them by lam like the tip loads.
  ForceTerms load_terms;
  load_terms.sde = false;
  VecX L;
  generalised_forces(model, q, v, a, load_terms, L);
  VecX r = F.head(model.flexible_dofs()) - (1.0 - lam) * L.head(model.flexible_dofs());
  r.segment<6>(model.rfe_index(n - 1)) -= lam * tip_generalised_force(model, q.segment<6>(model.rfe_index(n - 1)), loads);
  return r;
}

}  // namespace

StaticResult solve_static(const Model& model, const VecX& qb, const VecX& vb, const TipLoads& loads,
                          const StaticOptions& opts) {
  const int n = model.n(), m = model.m();
  StaticResult res;
  res.q = VecX::Zero(model.dof());
  model.joint_coords(res.q) = qb;
  if (n == 0) return res;
  VecX v = VecX::Zero(model.dof());
  model.joint_coords(v) = vb;
  const BorderedPattern pattern(n, 0);
  const std::vector<int> held(m, -1);
  CholmodSolver solver(pattern);
  MatrixTerms terms;
  terms.stiffness = 1.0;
  terms.gravity = true;
  terms.inertial = vb.size() > 0 && vb.norm() > 0.0;
  std::vector<double> values;

  // Load scale for the convergence test: the full load vector at the undeformed state.
  const double scale = std::max(residual(model, res.q, v, loads, 1.0).norm(), 1e-12);
  double lam = 0.0, step = 1.0;
  while (lam < 1.0) {
    const double target = std::min(1.0, lam + step);
    VecX q = res.q;
    bool ok = false;
    for (int it = 0; it < opts.max_iterations; ++it) {
      const VecX r = residual(model, q, v, loads, target);
      res.residual = r.norm();
      if (!std::isfinite(res.residual)) break;
      if (res.residual <= opts.tolerance * scale) {
        ok = true;
        break;
      }
      assemble_matrix(model, pattern, held, q, v, terms, values);
      if (!solver.factorize(values)) break;
      VecX dq = -r;
      solver.solve(dq);
      q.head(model.flexible_dofs()) += dq;
      ++res.iterations;
      // Converged when the correction is at round-off of the coordinates (the residual itself
      // cannot drop below round-off of the stiff axial springs, c Δx ~ 1e8 N/m × 1e-15 m).
      if (dq.lpNorm<Eigen::Infinity>() <= opts.step_tolerance * (1.0 + q.head(model.flexible_dofs()).lpNorm<Eigen::Infinity>())) {
        res.residual = residual(model, q, v, loads, target).norm();
        ok = std::isfinite(res.residual);
        break;
      }
    }
    if (ok) {
      res.q = q;
      lam = target;
      ++res.load_steps;
      step *= 2.0;
    } else {
      step *= 0.5;
      if (step < 1.0 / opts.max_load_steps)
        throw std::runtime_error("static equilibrium not found: Newton failed at load factor " +
                                 std::to_string(target) + " (residual " + std::to_string(res.residual) +
                                 " N); the link may buckle or the loads are too large");
    }
  }
  return res;
}

}  // namespace rfem
