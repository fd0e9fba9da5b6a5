#include "statics.hpp"
#include "../core/check.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "../assembly/assemble.hpp"
#include "../core/kinematics.hpp"
#include "../core/positions.hpp"
#include "../core/rotation.hpp"
#include "chain_solver.hpp"
#include "cholmod_solver.hpp"
#include "reduction.hpp"

namespace rfem {

Vec6 tip_generalised_force(const Model& model, int l, const Vec6& qn, const TipLoads& loads) {
  RFEM_CHECK_INDEX(l, model.links.size(), "link");
  DeformationTransform d;
  deformation_transform(qn, d);
  Vec6 Q;
  Q.head<3>() = loads.force;
  // Angular velocity of R = Ry Rz Rx in {r}: ω = Ry Rz e1 φ̇1 + e2 φ̇2 + Ry e3 φ̇3.
  const Mat3 Ry = rot_y(qn[4]), Ryz = Ry * rot_z(qn[5]);
  const Vec3 axes[3] = {Ryz.col(0), Vec3::UnitY(), Ry.col(2)};
  for (int a = 0; a < 3; ++a)
    Q[3 + a] = loads.force.dot(d.dR[a] * model.links[l].d.tip_eta) + loads.moment.dot(axes[a]);
  return Q;
}

int loaded_link(const Model& model, const TipLoads& loads) {
  const int nl = static_cast<int>(model.links.size());
  const int l = loads.link < 0 ? nl - 1 : loads.link;
  if (l < 0 || l >= nl) throw std::invalid_argument("tip loads on link " + std::to_string(l + 1) + ", which does not exist");
  return l;
}

VecX tip_load_forces(const Model& model, const VecX& q, const TipLoads& loads) {
  VecX Q = VecX::Zero(model.dof());
  if (loads.force.isZero(0.0) && loads.moment.isZero(0.0)) return Q;
  const int l = loaded_link(model, loads);
  const MountedLink& L = model.links[l];
  BaseKinematics bk, ref;
  const VecX z = VecX::Zero(model.dof());
  base_kinematics(model, q, z, z, bk);
  VecX q0 = q;  // the undeformed state: the loads' directions
  q0.head(model.flexible_dofs()).setZero();
  base_kinematics(model, q0, z, z, ref);
  const Mat3 R0 = bk.frame[l].B0.topLeftCorner<3, 3>(), Rref = ref.frame[l].B0.topLeftCorner<3, 3>();
  const Vec3 F = Rref * loads.force, M = Rref * loads.moment;  // in {0}
  if (L.n() > 0) {
    const int at = model.rfe_index(l, L.n() - 1);
    TipLoads own = loads;  // in the axes of {r} now (the same when {r} has not moved)
    if (R0 != Rref) {
      own.force = R0.transpose() * F;
      own.moment = R0.transpose() * M;
    }
    Q.segment<6>(at) = tip_generalised_force(model, l, q.segment<6>(at), own);
  }
  const Vec3 local = point_in_link_frame(model, l, L.d.length, q);  // the tip in {r}
  const Mat4& B0 = bk.frame[l].B0;
  const Vec4 p = B0 * Vec4(local[0], local[1], local[2], 1.0);
  for (int j : L.ancestors) {  // ∂p/∂q_j = (Ξ_j p)₁₋₃, ω_j = vee of Ξ_j's rotation
    const Mat4& X = bk.Xi[j];
    Q[model.nodes[j].coord] += F.dot((X * p).head<3>()) + M.dot(Vec3(X(2, 1), X(0, 2), X(1, 0)));
  }
  return Q;
}

namespace {

// Residual of the flexible rows at load factor lam: internal + gravity + centrifugal − tip loads.
VecX residual(const Model& model, const VecX& q, const VecX& v, const TipLoads& loads, double lam, Workspace& ws) {
  VecX F;
  const VecX a = VecX::Zero(model.dof());
  ForceTerms terms;
  generalised_forces(model, q, v, a, terms, F, nullptr, &ws);
  // Gravity and centrifugal forces are loads here: scale them by lam like the tip loads.
  ForceTerms load_terms;
  load_terms.sde = false;
  VecX L;
  generalised_forces(model, q, v, a, load_terms, L, nullptr, &ws);
  VecX r = F.head(model.flexible_dofs()) - (1.0 - lam) * L.head(model.flexible_dofs());
  r -= lam * tip_load_forces(model, q, loads).head(model.flexible_dofs());
  return r;
}

}  // namespace

StaticResult solve_static(const Model& model, const VecX& qb, const VecX& vb, const TipLoads& loads,
                          const StaticOptions& opts) {
  const int n = model.n(), m = model.m();
  if (qb.size() != m || (vb.size() != 0 && vb.size() != m))
    throw std::invalid_argument("solve_static: " + std::to_string(m) + " joint values and rates (or none) are required, got " +
                                std::to_string(qb.size()) + " and " + std::to_string(vb.size()));
  StaticResult res;
  res.q = VecX::Zero(model.dof());
  model.joint_coords(res.q) = qb;
  if (n == 0) return res;
  VecX v = VecX::Zero(model.dof());
  if (vb.size()) model.joint_coords(v) = vb;
  const std::vector<int> held(m, -1);
  const auto shared_pattern = std::make_shared<const BorderedPattern>(model, held);
  const BorderedPattern& pattern = *shared_pattern;
  std::shared_ptr<const Reduction> own;  // reduced links: Newton on η, q = q0 + Φ η
  const Reduction* red = opts.reduction;
  if (!red && (own = Reduction::of(model, qb, opts.parallel))) red = own.get();
  const int n6 = model.flexible_dofs(), nu = red ? red->rfe() : n6;
  // The chain solver (Cholesky: O(n), in place, no analysis) while the stiffness is positive
  // definite; CHOLMOD's LDLᵀ once it is not (a spinning link's centrifugal softening). CHOLMOD's
  // analysis and the pattern's CSC copy take 4.4 kB per rfe, above a run's 2 kB: only when needed.
  ChainSolver chain(shared_pattern);
  chain.set_threads(opts.parallel.team(n));
  std::unique_ptr<CholmodSolver> cholmod;
  ReducedFactor reduced;
  std::unique_ptr<Projection> projection;
  if (red) projection = std::make_unique<Projection>(*red, pattern);
  MatrixTerms terms;
  terms.stiffness = 1.0;
  terms.gravity = true;
  terms.inertial = vb.size() > 0 && vb.norm() > 0.0;
  std::vector<double> values;
  Workspace ws(model, opts.parallel);  // the Newton iteration's scratch, cut once
  auto project = [&](const VecX& r) {
    if (!red) return r;
    VecX p(nu);
    red->project(r.data(), p.data(), 0);
    return p;
  };

  // Load scale for the convergence test: the full load vector at the undeformed state.
  const double scale = std::max(project(residual(model, res.q, v, loads, 1.0, ws)).norm(), 1e-12);
  VecX eta = VecX::Zero(nu);  // the unknowns: every rfe coordinate, or the reduced ones
  if (red) red->lift(eta.data(), res.q.data(), 0, true);  // η = 0: the equilibrium the modes are taken about
  else eta = res.q.head(n6);
  double lam = 0.0, step = 1.0;
  while (lam < 1.0) {
    const double target = std::min(1.0, lam + step);
    VecX q = res.q, x = eta;
    bool ok = false;
    for (int it = 0; it < opts.max_iterations; ++it) {
      const VecX r = project(residual(model, q, v, loads, target, ws));
      res.residual = r.norm();
      if (!std::isfinite(res.residual)) break;
      if (res.residual <= opts.tolerance * scale) {
        ok = true;
        break;
      }
      assemble_matrix(model, pattern, held, q, v, terms, values, &ws);
      VecX dq = -r;
      if (red) {
        if (!reduced.factorize(projection->reduce(values), red->kept(), false, opts.parallel.team(n))) break;
        reduced.solve(dq, opts.parallel.team(n));
      } else {
        if (!cholmod && !chain.factorize(values)) {  // not positive definite: LDLᵀ from now on
          cholmod = std::make_unique<CholmodSolver>(shared_pattern);
          assemble_matrix(model, pattern, held, q, v, terms, values, &ws);  // (factorised in place)
        }
        if (cholmod && !cholmod->factorize(values)) break;
        if (cholmod) cholmod->solve(dq);
        else chain.solve(dq);
      }
      x += dq;
      if (red) red->lift(x.data(), q.data(), 0, true);
      else q.head(n6) = x;
      ++res.iterations;
      // Converged when the correction is at round-off of the coordinates (the residual itself
      // cannot drop below round-off of the stiff axial springs, c Δx ~ 1e8 N/m × 1e-15 m).
      if (dq.lpNorm<Eigen::Infinity>() <= opts.step_tolerance * (1.0 + x.lpNorm<Eigen::Infinity>())) {
        res.residual = project(residual(model, q, v, loads, target, ws)).norm();
        ok = std::isfinite(res.residual);
        break;
      }
    }
    if (ok) {
      res.q = q;
      eta = x;
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
