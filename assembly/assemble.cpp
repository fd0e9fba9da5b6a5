#include "assembly/assemble.hpp"

#include <omp.h>

#include "assembly/rfe_kernels.hpp"
#include "assembly/sde_kernels.hpp"

namespace rfem {

namespace {

constexpr int kChunk = 64;  // rfes per reduction chunk (fixed: thread-count independent sums)
int g_parallel_min = 256;  // below this many rfes a parallel region costs more than it saves

struct BaseMoments {  // Σ over bodies of Y = W H Ẅᵀ, G = W H Wᵀ, s = W H e₄
  Mat4 Y = Mat4::Zero(), G = Mat4::Zero();
  Vec4 s = Vec4::Zero();
  BaseMoments& operator+=(const BaseMoments& o) {
    Y += o.Y;
    G += o.G;
    s += o.s;
    return *this;
  }
};

// rfe_0's rotation (zero coordinates): R = I, ∂R/∂φ the generators.
const RfeRotation& clamp_rotation() {
  static const RfeRotation r = [] {
    DeformationTransform d;
    deformation_transform(Vec6::Zero(), d, false);
    return rfe_rotation(d);
  }();
  return r;
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

void set_parallel_min_rfes(int n) { g_parallel_min = n; }

void generalised_forces(const Model& model, const VecX& q, const VecX& v, const VecX& a,
                        const ForceTerms& terms, VecX& F) {
  const int n = model.n(), m = model.m();
  const Discretisation& d = model.link;
  const double g = terms.gravity ? model.gravity : 0.0;
  F.setZero(model.dof());
  const VecX zero_v = terms.velocity_products ? VecX() : VecX::Zero(model.dof());
  const VecX& vi = terms.velocity_products ? v : zero_v;  // velocity seen by the inertial terms
  BaseKinematics bk;
  base_kin(model, q, vi, a, bk);
  const int nchunks = (n + kChunk - 1) / kChunk;
  std::vector<BaseMoments> chunk(nchunks);
  // Each rfe's rotation, evaluated once here and reused by both sdes that touch it. The buffer is
  // per calling thread; the reference (shared in the parallel regions) names the caller's buffer.
  thread_local std::vector<RfeRotation> rotation_buffer;
  std::vector<RfeRotation>& rotations = rotation_buffer;
  rotations.resize(n);
#pragma omp parallel for schedule(static) if (n >= g_parallel_min)
  for (int c = 0; c < nchunks; ++c) {
    RfePose pose;
    for (int k = c * kChunk; k < std::min(n, (c + 1) * kChunk); ++k) {
      rfe_pose(d.rfes[k], bk, rfe_coords(q, k), rfe_coords(vi, k), rfe_coords(a, k), pose);
      rotations[k] = rfe_rotation(pose.d);
      Vec6 f = Vec6::Zero(), fg;
      Mat4 Y;
      Vec4 s;
      if (terms.inertia) {
        rfe_inertial_force(d.rfes[k], pose, f, Y);
        chunk[c].Y += Y;
      }
      rfe_gravity_force(d.rfes[k], pose, g, fg, s);
      chunk[c].s += s;
      F.segment<6>(6 * k) = f + fg;
    }
  }
  if (terms.sde) {
    const double beta = d.damping_beta;
    for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(static) if (n >= g_parallel_min)
      for (int e = colour; e < n; e += 2) {
        const Sde& s = d.sdes[e];
        const Vec6 ql = left_coords(q, e), vl = left_coords(v, e);
        SdeResult r;
        sde_forces(s, left_centre(d, s), d.rfes[e].centre, beta, ql, vl, rfe_coords(q, e), rfe_coords(v, e),
                   e > 0 ? rotations[e - 1] : clamp_rotation(), rotations[e], r);
        if (e > 0) F.segment<6>(6 * (e - 1)) += r.f.head<6>();
        F.segment<6>(6 * e) += r.f.tail<6>();
      }
    }
  }
  BaseMoments flex;
  for (const auto& c : chunk) flex += c;
  if (!terms.inertia) flex.Y.setZero();
  const auto S = suffix_moments(model, bk, flex);
  for (int j = 0; j < m; ++j) {
    double eps = terms.inertia ? trace_prod(bk.Xi[j], S[j].Y) : 0.0;
    F[6 * n + j] = eps + g * (bk.Xi[j] * S[j].s)[2];
  }
}

void assemble_matrix(const Model& model, const BorderedPattern& pattern, const std::vector<int>& base_col,
                     const VecX& q, const VecX& v, const MatrixTerms& t, std::vector<double>& values,
                     std::vector<double>* sde_stiffness) {
  const int n = model.n(), m = model.m();
  const Discretisation& d = model.link;
  values.assign(pattern.nnz(), 0.0);
  if (sde_stiffness) sde_stiffness->assign(pattern.nnz(), 0.0);
  BaseKinematics bk;
  const VecX zero = VecX::Zero(model.dof());
  base_kin(model, q, v, zero, bk);
  const double g = t.gravity ? model.gravity : 0.0;
  const int nchunks = (n + kChunk - 1) / kChunk;
  std::vector<BaseMoments> chunk(nchunks);
#pragma omp parallel for schedule(static) if (n >= g_parallel_min)
  for (int c = 0; c < nchunks; ++c) {
    RfePose pose;
    Mat6 Mkk;
    MatX border;
    Mat4 G;
    for (int k = c * kChunk; k < std::min(n, (c + 1) * kChunk); ++k) {
      const Rfe& rfe = d.rfes[k];
      rfe_pose(rfe, bk, rfe_coords(q, k), rfe_coords(v, k), rfe_coords(zero, k), pose);
      rfe_mass_blocks(rfe, pose, bk, Mkk, border, G);
      chunk[c].G += G;
      chunk[c].s += pose.W * rfe.H.col(3);
      Mat6 blk = t.mass * Mkk;
      border *= t.mass;
      if (t.inertial) blk += t.stiffness * rfe_inertial_stiffness(rfe, pose, bk);
      if (g != 0.0) {
        MatX gb = MatX::Zero(m, 6);
        rfe_gravity_border(rfe, pose, bk, g, gb);
        border += t.stiffness * gb;
      }
      for (int l = 0; l < 6; ++l)
        for (int j = 0; j <= l; ++j) values[pattern.slot(6 * k + j, 6 * k + l)] = blk(j, l);
      for (int j = 0; j < m; ++j)
        if (base_col[j] >= 0)
          for (int l = 0; l < 6; ++l) values[pattern.slot(6 * k + l, base_col[j])] = border(j, l);
    }
  }
  for (int colour = 0; colour < 2; ++colour) {
#pragma omp parallel for schedule(static) if (n >= g_parallel_min)
    for (int e = colour; e < n; e += 2) {
      const Sde& s = d.sdes[e];
      Mat12 S = Mat12::Zero(), K = Mat12::Zero();
      const Vec6 ql = left_coords(q, e);
      sde_matrix(s, left_centre(d, s), d.rfes[e].centre, d.damping_beta, ql, rfe_coords(q, e), t.stiffness,
                 t.damping, S, sde_stiffness ? &K : nullptr);
      const int p0 = 6 * e, l0 = 6 * (e - 1);
      auto scatter = [&](const Mat12& A, std::vector<double>& vals) {
        for (int b = 0; b < 6; ++b)
          for (int a = 0; a <= b; ++a) vals[pattern.slot(p0 + a, p0 + b)] += A(6 + a, 6 + b);
        if (e > 0) {
          for (int b = 0; b < 6; ++b)
            for (int a = 0; a <= b; ++a) vals[pattern.slot(l0 + a, l0 + b)] += A(a, b);
          for (int b = 0; b < 6; ++b)
            for (int a = 0; a < 6; ++a) vals[pattern.slot(l0 + a, p0 + b)] += A(a, 6 + b);
        }
      };
      scatter(S, values);
      if (sde_stiffness) scatter(K, *sde_stiffness);
    }
  }
  BaseMoments flex;
  for (const auto& c : chunk) flex += c;
  const auto S = suffix_moments(model, bk, flex);
  for (int j = 0; j < m; ++j)
    for (int l = j; l < m; ++l) {
      if (base_col[j] < 0 || base_col[l] < 0) continue;
      const int hi = std::max(j, l);
      double val = t.mass * trace_prod(bk.Xi[j] * S[hi].G, bk.Xi[l].transpose());
      if (g != 0.0) val += t.stiffness * g * (bk.Xi[j] * bk.Xi[l] * S[hi].s)[2];
      const int r = std::min(base_col[j], base_col[l]), c = std::max(base_col[j], base_col[l]);
      values[pattern.slot(r, c)] += val;
    }
}

MatX to_dense(const BorderedPattern& pattern, const std::vector<double>& values) {
  MatX A = MatX::Zero(pattern.size(), pattern.size());
  for (int c = 0; c < pattern.size(); ++c)
    for (long p = pattern.colptr()[c]; p < pattern.colptr()[c + 1]; ++p) {
      const long r = pattern.rowind()[p];
      A(r, c) = A(c, r) = values[p];
    }
  return A;
}

Energies energies(const Model& model, const VecX& q, const VecX& v) {
  const int n = model.n(), m = model.m();
  const Discretisation& d = model.link;
  Energies E;
  BaseKinematics bk;
  const VecX zero = VecX::Zero(model.dof());
  base_kin(model, q, v, zero, bk);
  for (int i = 0; i < m; ++i) {
    const Mat4& H = model.joints[i].H;
    E.kinetic += 0.5 * trace_prod(bk.Wd[i] * H, bk.Wd[i].transpose());
    E.gravity += model.gravity * (bk.W[i] * H.col(3))[2];
  }
  double T = 0.0, Vg = 0.0, Ve = 0.0, Pd = 0.0;
#pragma omp parallel for schedule(static) reduction(+ : T, Vg, Ve, Pd) if (n >= g_parallel_min)
  for (int k = 0; k < n; ++k) {
    RfePose pose;
    rfe_pose(d.rfes[k], bk, rfe_coords(q, k), rfe_coords(v, k), rfe_coords(zero, k), pose);
    T += rfe_kinetic_energy(d.rfes[k], pose, bk, rfe_coords(v, k));
    Vg += model.gravity * (pose.W * d.rfes[k].H.col(3))[2];
    const Sde& s = d.sdes[k];
    SdeResult r;
    const Vec6 ql = left_coords(q, k), vl = left_coords(v, k);
    sde_forces(s, left_centre(d, s), d.rfes[k].centre, d.damping_beta, ql, vl, rfe_coords(q, k), rfe_coords(v, k), r);
    Ve += r.V;
    Pd += r.P_d;
  }
  E.kinetic += T;
  E.gravity += Vg;
  E.elastic = Ve;
  E.dissipation_rate = Pd;
  return E;
}

}  // namespace rfem
