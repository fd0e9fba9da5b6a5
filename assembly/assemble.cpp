#include "assembly/assemble.hpp"

#include <omp.h>

#include "assembly/rfe_kernels.hpp"
#include "assembly/sde_kernels.hpp"

namespace rfem {

int Parallelism::team(int n) const {
  if (n < min_rfes) return 1;
  return threads > 0 ? threads : omp_get_max_threads();
}

int Workspace::chunks(int n) {
  const int c = (n + parallel.chunk - 1) / parallel.chunk;
  moments.assign(c, BaseMoments{});
  power.assign(c, 0.0);
  boundary.assign(c, Vec6::Zero());
  return c;
}

namespace {

// rfe_0's rotation (zero coordinates): R = I, ∂R/∂φ the generators.
const RfeRotation& clamp_rotation() {
  static const RfeRotation r = [] {
    DeformationTransform d;
    deformation_transform(Vec6::Zero(), d, false);
    return rfe_rotation(d);
  }();
  return r;
}

RfeRotation rotation_of(const Vec6& q) {
  DeformationTransform d;
  deformation_transform(q, d, false);
  return rfe_rotation(d);
}

Vec3 left_centre(const Discretisation& d, const Sde& e) {
  return e.left < 0 ? d.rfe0.centre : d.rfes[e.left].centre;
}

// Suffix sums over base links: moments of every body moved by joint j (links j … m and the
// flexible link).
std::vector<BaseMoments> suffix_moments(const Model& model, const BaseKinematics& bk,
                                        const BaseMoments& flexible) {
  const int m = model.m();
  std::vector<BaseMoments> S(m + 1);
  S[m] = flexible;
  for (int i = m - 1; i >= 0; --i) {
    const Mat4 WH = bk.W[i] * model.joints[i].H;
    BaseMoments b;
    b.Y = WH * bk.Wdd[i].transpose();
    b.G = WH * bk.W[i].transpose();
    b.s = WH.col(3);
    S[i] = S[i + 1];
    S[i] += b;
  }
  return S;
}

void base_kin(const Model& model, const VecX& q, const VecX& v, const VecX& a, BaseKinematics& bk) {
  base_kinematics(model, base_coords(model, q), base_coords(model, v), base_coords(model, a), bk);
}

}  // namespace

void generalised_forces(const Model& model, const VecX& q, const VecX& v, const VecX& a,
                        const ForceTerms& terms, VecX& F, double* dissipation, Workspace* wsp) {
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  const int n = model.n(), m = model.m();
  const Discretisation& d = model.link;
  const double g = terms.gravity ? model.gravity : 0.0, beta = d.damping_beta;
  F.resize(model.dof());
  if (!terms.velocity_products && ws.zero.size() != model.dof()) ws.zero = VecX::Zero(model.dof());
  const VecX& vi = terms.velocity_products ? v : ws.zero;  // velocity seen by the inertial terms
  BaseKinematics& bk = ws.bk;
  base_kin(model, q, vi, a, bk);
  const int nchunks = ws.chunks(n);
  // One pass per chunk: rfe k's pose and forces, then sde k (rfes k−1, k) with both rotations —
  // each rotation is evaluated once, except the one of the rfe before the chunk.
#pragma omp parallel for schedule(dynamic, 1) num_threads(ws.parallel.team(n))
  for (int c = 0; c < nchunks; ++c) {
    DeformationTransform dt;
    const int k0 = ws.chunk_begin(c), k1 = ws.chunk_end(c, n);
    RfeRotation left = k0 > 0 ? rotation_of(rfe_coords(model, q, k0 - 1)) : clamp_rotation();
    BaseMoments& mom = ws.moments[c];
    const Mat3 R0 = bk.B0.topLeftCorner<3, 3>();
    for (int k = k0; k < k1; ++k) {
      const Rfe& rfe = d.rfes[k];
      const Vec6 qk = rfe_coords(model, q, k);
      deformation_transform(qk, dt, false);
      const Vec3 p = bk.B0.topLeftCorner<3, 3>() * (rfe.centre + qk.head<3>()) + bk.B0.topRightCorner<3, 1>();
      Vec6 f = Vec6::Zero();
      if (terms.inertia) {
        Vec3 fi, ni;
        rfe_inertia(rfe, bk, dt, rfe_coords(model, vi, k), rfe_coords(model, a, k), p, f, fi, ni);
        mom.f += fi;
        mom.n += ni;
      }
      f.head<3>() += g * rfe.mass * R0.row(2).transpose();  // gravity on the mass centre
      mom.s += rfe.mass * Vec4(p[0], p[1], p[2], 1.0);
      F.segment<6>(model.rfe_index(k)) = f;
      const RfeRotation right = rfe_rotation(dt);
      if (terms.sde) {
        const Sde& e = d.sdes[k];
        SdeResult r;
        sde_forces(e, left_centre(d, e), rfe.centre, beta, left_coords(model, q, k), left_coords(model, v, k), qk,
                   rfe_coords(model, v, k), left, right, r);
        if (k == k0) {
          if (k > 0) ws.boundary[c] = r.f.head<6>();  // rfe k−1 belongs to the previous chunk
        } else {
          F.segment<6>(model.rfe_index(k - 1)) += r.f.head<6>();
        }
        F.segment<6>(model.rfe_index(k)) += r.f.tail<6>();
        ws.power[c] += r.P_d;
      }
      left = right;
    }
  }
  BaseMoments flex;
  double Pd = 0.0;
  for (int c = 0; c < nchunks; ++c) {
    if (c > 0 && terms.sde) F.segment<6>(model.rfe_index(ws.chunk_begin(c) - 1)) += ws.boundary[c];
    flex += ws.moments[c];
    Pd += ws.power[c];
  }
  const auto S = suffix_moments(model, bk, flex);
  for (int j = 0; j < m; ++j) {
    const Mat4& X = bk.Xi[j];
    double eps = 0.0;
    if (terms.inertia)  // rigid links through Y; the rfes through their wrench and joint j's unit twist
      eps = trace_prod(X, S[j].Y) + Vec3(X(2, 1), X(0, 2), X(1, 0)).dot(flex.n) + X.topRightCorner<3, 1>().dot(flex.f);
    F[model.joint_index(j)] = eps + g * (X * S[j].s)[2];
    const JointDrive& dr = model.joints[j].drive;
    if (!dr.active()) continue;
    const double vj = v[model.joint_index(j)];
    if (terms.inertia) F[model.joint_index(j)] += dr.inertia * a[model.joint_index(j)];
    if (terms.sde) {
      F[model.joint_index(j)] += dr.dissipative_force(vj);
      Pd += dr.power(vj);
    }
  }
  if (dissipation) *dissipation = Pd;
}

namespace {

using RowMat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;
using Block = Eigen::Map<RowMat6>;

// Adds sde e's 12×12 matrix f·A (coordinates [rfe e−1; rfe e]) to `vals`: D_e, E_e and D_{e−1}
// (into *left instead when given: that rfe belongs to another chunk).
void scatter_sde(const BorderedPattern& p, int e, const Mat12& A, std::vector<double>& vals, Mat6* left) {
  Block(vals.data() + p.diag(e)) += A.bottomRightCorner<6, 6>();
  if (e == 0) return;
  Block(vals.data() + p.coupling(e)) += A.topRightCorner<6, 6>();
  if (left) *left = A.topLeftCorner<6, 6>();
  else Block(vals.data() + p.diag(e - 1)) += A.topLeftCorner<6, 6>();
}

}  // namespace

void assemble_matrices(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                       const VecX& q, const VecX& v, const MatrixTerms& t, std::vector<double>& values,
                       const std::vector<SdeTarget>& extra, MatX* base_rows, Workspace* wsp) {
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  const int n = model.n(), m = model.m(), nb = pattern.n_base(), ne = static_cast<int>(extra.size());
  const Discretisation& d = model.link;
  values.assign(pattern.nnz(), 0.0);
  for (const auto& x : extra) x.values->assign(pattern.nnz(), 0.0);
  if (ws.zero.size() != model.dof()) ws.zero = VecX::Zero(model.dof());
  const VecX& zero = ws.zero;
  BaseKinematics& bk = ws.bk;
  base_kin(model, q, v, zero, bk);
  const double g = t.gravity ? model.gravity : 0.0;
  const bool sdes = t.stiffness != 0.0 || t.damping != 0.0 || ne > 0;
  bool damping = d.damping_beta != 0.0 && t.damping != 0.0;
  for (const auto& x : extra) damping |= d.damping_beta != 0.0 && x.fc != 0.0;
  const bool second = sdes || t.inertial;  // the geometric stiffness and the centrifugal one need ∂²R
  const int nchunks = ws.chunks(n);
  ws.boundary_block.assign(static_cast<size_t>(nchunks) * (1 + ne), Mat6::Zero());
  if (base_rows) base_rows->setZero(m, pattern.size());
  std::vector<int> col(m);  // joint → border column (−1 if held)
  for (int j = 0; j < m; ++j) col[j] = base_col[j] >= 0 ? base_col[j] - model.flexible_dofs() : -1;
#pragma omp parallel for schedule(dynamic, 1) num_threads(ws.parallel.team(n))
  for (int c = 0; c < nchunks; ++c) {
    RfePose pose;
    Mat6 Mkk;
    MatX border, gb;
    Mat4 G;
    Mat12 Ke, Ce, A;
    DeformationTransform left;  // the rfe before, for the sde between them
    const int k0 = ws.chunk_begin(c);
    if (sdes) deformation_transform(k0 > 0 ? rfe_coords(model, q, k0 - 1) : Vec6::Zero().eval(), left, true);
    for (int k = k0; k < ws.chunk_end(c, n); ++k) {
      const Rfe& rfe = d.rfes[k];
      rfe_pose(rfe, bk, rfe_coords(model, q, k), rfe_coords(model, v, k), rfe_coords(model, zero, k), pose, t.inertial, second);
      rfe_mass_blocks(rfe, pose, bk, Mkk, border, G);
      ws.moments[c].G += G;
      ws.moments[c].s += pose.W * rfe.H.col(3);
      Mat6 blk = t.mass * Mkk;
      border *= t.mass;
      if (base_rows) base_rows->middleCols<6>(model.rfe_index(k)) = border;
      if (t.inertial) blk += t.stiffness * rfe_inertial_stiffness(rfe, pose, bk);
      if (g != 0.0) {
        gb.setZero(m, 6);
        rfe_gravity_border(rfe, pose, bk, g, gb);
        border += t.stiffness * gb;
      }
      Block(values.data() + pattern.diag(k)) = blk;
      for (int j = 0; j < m; ++j)
        if (col[j] >= 0)
          for (int l = 0; l < 6; ++l) values[pattern.border(k) + static_cast<long>(l) * nb + col[j]] = border(j, l);
      if (!sdes) continue;
      const Sde& e = d.sdes[k];
      sde_matrices(e, left_centre(d, e), rfe.centre, d.damping_beta, left_coords(model, q, k), rfe_coords(model, q, k), left, pose.d,
                   Ke, damping ? &Ce : nullptr);
      const bool first = k == k0 && k > 0;  // its left rfe belongs to the previous chunk
      const size_t bslot = static_cast<size_t>(c) * (1 + ne);
      A = t.stiffness * Ke;
      if (damping) A += t.damping * Ce;
      scatter_sde(pattern, k, A, values, first ? &ws.boundary_block[bslot] : nullptr);
      for (int i = 0; i < ne; ++i) {
        A = extra[i].fk * Ke;
        if (damping) A += extra[i].fc * Ce;
        scatter_sde(pattern, k, A, *extra[i].values, first ? &ws.boundary_block[bslot + 1 + i] : nullptr);
      }
      left = pose.d;
    }
  }
  if (sdes)
    for (int c = 1; c < nchunks; ++c) {
      const int k = ws.chunk_begin(c) - 1;
      const size_t bslot = static_cast<size_t>(c) * (1 + ne);
      Block(values.data() + pattern.diag(k)) += ws.boundary_block[bslot];
      for (int i = 0; i < ne; ++i) Block(extra[i].values->data() + pattern.diag(k)) += ws.boundary_block[bslot + 1 + i];
    }
  BaseMoments flex;
  for (const auto& c : ws.moments) flex += c;
  const auto S = suffix_moments(model, bk, flex);
  for (int j = 0; j < m; ++j)
    for (int l = 0; l < m; ++l) {
      if (col[l] < 0) continue;  // columns are unknowns only
      const int hi = std::max(j, l);
      double mass = t.mass * trace_prod(bk.Xi[j] * S[hi].G, bk.Xi[l].transpose());
      if (j == l) mass += t.mass * model.joints[j].drive.inertia;
      if (base_rows) (*base_rows)(j, base_col[l]) = mass;
      if (col[j] < 0 || l < j) continue;
      double val = mass;
      if (g != 0.0) val += t.stiffness * g * (bk.Xi[j] * bk.Xi[l] * S[hi].s)[2];
      if (j == l && t.damping != 0.0) val += t.damping * model.joints[j].drive.damping_derivative(v[model.joint_index(j)]);
      values[pattern.base() + static_cast<long>(std::min(col[j], col[l])) * nb + std::max(col[j], col[l])] += val;
    }
}

void assemble_matrix(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                     const VecX& q, const VecX& v, const MatrixTerms& t, std::vector<double>& values, Workspace* ws) {
  assemble_matrices(model, pattern, base_col, q, v, t, values, {}, nullptr, ws);
}

Energies energies(const Model& model, const VecX& q, const VecX& v, Workspace* wsp) {
  Workspace local;
  Workspace& ws = wsp ? *wsp : local;
  const int n = model.n(), m = model.m();
  const Discretisation& d = model.link;
  Energies E;
  if (ws.zero.size() != model.dof()) ws.zero = VecX::Zero(model.dof());
  BaseKinematics& bk = ws.bk;
  base_kin(model, q, v, ws.zero, bk);
  for (int i = 0; i < m; ++i) {
    const Mat4& H = model.joints[i].H;
    E.kinetic += 0.5 * trace_prod(bk.Wd[i] * H, bk.Wd[i].transpose());
    E.gravity += model.gravity * (bk.W[i] * H.col(3))[2];
    const double vi = v[model.joint_index(i)];
    E.kinetic += model.joints[i].drive.kinetic_energy(vi);
    E.dissipation_rate += model.joints[i].drive.power(vi);
  }
  const int nchunks = ws.chunks(n);
  std::vector<Eigen::Vector4d> part(nchunks, Eigen::Vector4d::Zero());  // T, V_g, V_e, P_d per chunk
#pragma omp parallel for schedule(dynamic, 1) num_threads(ws.parallel.team(n))
  for (int c = 0; c < nchunks; ++c) {
    RfePose pose;
    for (int k = ws.chunk_begin(c); k < ws.chunk_end(c, n); ++k) {
      rfe_pose(d.rfes[k], bk, rfe_coords(model, q, k), rfe_coords(model, v, k), rfe_coords(model, ws.zero, k), pose, false);
      const Sde& s = d.sdes[k];
      SdeResult r;
      sde_forces(s, left_centre(d, s), d.rfes[k].centre, d.damping_beta, left_coords(model, q, k), left_coords(model, v, k),
                 rfe_coords(model, q, k), rfe_coords(model, v, k), r);
      part[c] += Eigen::Vector4d(rfe_kinetic_energy(d.rfes[k], pose, bk, rfe_coords(model, v, k)),
                                 model.gravity * (pose.W * d.rfes[k].H.col(3))[2], r.V, r.P_d);
    }
  }
  Eigen::Vector4d sum = Eigen::Vector4d::Zero();
  for (const auto& p : part) sum += p;  // chunk order: the same bits for any thread count
  E.kinetic += sum[0];
  E.gravity += sum[1];
  E.elastic = sum[2];
  E.dissipation_rate += sum[3];
  return E;
}

}  // namespace rfem
