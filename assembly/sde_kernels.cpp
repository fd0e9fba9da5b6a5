#include "sde_kernels.hpp"

namespace rfem {

namespace {

struct SdeGeometry {
  Eigen::Matrix<double, 3, 12> J;  ///< ∂Δx/∂q
  Vec3 dx;                         ///< Δx
  DeformationTransform dl, dp;
};

// Δx and J from both rfes' rotations.
void displacement(const Sde& e, const Vec3& cl, const Vec3& cr, const Vec6& ql, const Vec6& qp, const RfeRotation& rl,
                  const RfeRotation& rp, Vec3& dx, Eigen::Matrix<double, 3, 12>& J) {
  const bool has_left = e.left >= 0;
  const Vec3 pl = cl + rl.R * e.eta_left + (has_left ? ql.head<3>() : Vec3::Zero().eval());
  const Vec3 pr = cr + rp.R * e.eta_right + qp.head<3>();
  dx = pr - pl;
  J.setZero();
  J.block<3, 3>(0, 6) = Mat3::Identity();
  for (int a = 0; a < 3; ++a) J.col(9 + a) = rp.dR[a] * e.eta_right;
  if (has_left) {
    J.block<3, 3>(0, 0) = -Mat3::Identity();
    for (int a = 0; a < 3; ++a) J.col(3 + a) = -(rl.dR[a] * e.eta_left);
  }
}

// `second`: also ∂²R/∂φ² (the geometric stiffness needs it, the forces do not).
void geometry(const Sde& e, const Vec3& cl, const Vec3& cr, const Vec6& ql, const Vec6& qp, SdeGeometry& g,
              bool second) {
  deformation_transform(e.left >= 0 ? ql : Vec6::Zero().eval(), g.dl, second);
  deformation_transform(qp, g.dp, second);
  displacement(e, cl, cr, ql, qp, rfe_rotation(g.dl), rfe_rotation(g.dp), g.dx, g.J);
}

}  // namespace

void sde_forces(const Sde& e, const Vec3& cl, const Vec3& cr, double beta, const Vec6& ql, const Vec6& vl,
                const Vec6& qp, const Vec6& vp, SdeResult& out) {
  DeformationTransform dl, dp;
  deformation_transform(e.left >= 0 ? ql : Vec6::Zero().eval(), dl, false);
  deformation_transform(qp, dp, false);
  sde_forces(e, cl, cr, beta, ql, vl, qp, vp, rfe_rotation(dl), rfe_rotation(dp), out);
}

void sde_forces(const Sde& e, const Vec3& cl, const Vec3& cr, double beta, const Vec6& ql, const Vec6& vl,
                const Vec6& qp, const Vec6& vp, const RfeRotation& rl, const RfeRotation& rp, SdeResult& out) {
  // displacement()'s J written by its blocks (±I for the translations, Jl, Jr for the rotations): this
  // runs for every sde in every residual, and most of J is zeros and identities.
  const bool has_left = e.left >= 0;
  Mat3 Jl, Jr;
  for (int a = 0; a < 3; ++a) Jr.col(a) = rp.dR[a] * e.eta_right;
  const Vec3 pr = cr + rp.R * e.eta_right + qp.head<3>();
  Vec3 pl = cl + rl.R * e.eta_left, dx_dot = vp.head<3>() + Jr * vp.tail<3>();
  Vec3 dphi = qp.tail<3>(), dphi_dot = vp.tail<3>();
  if (has_left) {
    for (int a = 0; a < 3; ++a) Jl.col(a) = rl.dR[a] * e.eta_left;
    pl += ql.head<3>();
    dx_dot -= vl.head<3>() + Jl * vl.tail<3>();
    dphi -= ql.tail<3>();
    dphi_dot -= vl.tail<3>();
  }
  const Vec3 dx = pr - pl;
  const Vec3 lam = e.c.cwiseProduct(dx + beta * dx_dot);     // spring + damper force
  const Vec3 mu = e.k.cwiseProduct(dphi + beta * dphi_dot);  // spring + damper moment
  out.f.segment<3>(6) = lam;
  out.f.segment<3>(9) = Jr.transpose() * lam + mu;
  if (has_left) {
    out.f.head<3>() = -lam;
    out.f.segment<3>(3) = -(Jl.transpose() * lam) - mu;
  } else {
    out.f.head<6>().setZero();
  }
  out.V = 0.5 * dx.dot(e.c.cwiseProduct(dx)) + 0.5 * dphi.dot(e.k.cwiseProduct(dphi));
  out.P_d = beta * (dx_dot.dot(e.c.cwiseProduct(dx_dot)) + dphi_dot.dot(e.k.cwiseProduct(dphi_dot)));
}

namespace {

// The Gauss–Newton part Jᵀ c J + rotational springs ("base", C = β base) and the geometric part
// Σ_i λ_i ∂²Δx_i/∂φ∂φ, λ = c Δx (the spring force turning with the rfe) of the stiffness.
void sde_parts(const Sde& e, const Vec3& cl, const Vec3& cr, const Vec6& ql, const Vec6& qp, Mat12& base, Mat12& geo) {
  SdeGeometry g;
  geometry(e, cl, cr, ql, qp, g, true);
  base.noalias() = g.J.transpose() * e.c.asDiagonal() * g.J;
  for (int a = 0; a < 3; ++a) {
    base(3 + a, 3 + a) += e.k[a];
    base(9 + a, 9 + a) += e.k[a];
    base(3 + a, 9 + a) -= e.k[a];
    base(9 + a, 3 + a) -= e.k[a];
  }
  if (e.left < 0) {
    base.topRows<6>().setZero();
    base.leftCols<6>().setZero();
  }
  geo.setZero();
  const Vec3 lam = e.c.cwiseProduct(g.dx);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      geo(9 + a, 9 + b) = lam.dot(g.dp.ddR[a][b] * e.eta_right);
      if (e.left >= 0) geo(3 + a, 3 + b) = -lam.dot(g.dl.ddR[a][b] * e.eta_left);
    }
}

}  // namespace

void sde_matrices(const Sde& e, const Vec3& cl, const Vec3& cr, double beta, const Vec6& ql, const Vec6& qp,
                  Mat12& K, Mat12* C) {
  Mat12 base, geo;
  sde_parts(e, cl, cr, ql, qp, base, geo);
  K = base + geo;
  if (C) *C = beta * base;
}

void sde_matrices(const Sde& e, const Vec3& cl, const Vec3& cr, double beta, const Vec6& ql, const Vec6& qp,
                  const DeformationTransform& dl, const DeformationTransform& dp, Mat12& K, Mat12* C) {
  const bool has_left = e.left >= 0;
  const Mat3 Rl = dl.D.topLeftCorner<3, 3>(), Rp = dp.D.topLeftCorner<3, 3>();
  Mat3 Al, Ap;
  for (int a = 0; a < 3; ++a) {
    Al.col(a) = dl.dR[a] * e.eta_left;
    Ap.col(a) = dp.dR[a] * e.eta_right;
  }
  const Vec3 dx = cr + Rp * e.eta_right + qp.head<3>() - cl - Rl * e.eta_left - (has_left ? ql.head<3>() : Vec3::Zero().eval());
  const auto c = e.c.asDiagonal();
  const Mat3 cAl = c * Al, cAp = c * Ap, cm = e.c.asDiagonal();
  const Mat3 kd = e.k.asDiagonal();
  Mat12 B = Mat12::Zero();  // Jᵀ c J + rotational springs, upper and lower blocks
  B.block<3, 3>(6, 6) = cm;
  B.block<3, 3>(6, 9) = cAp;
  B.block<3, 3>(9, 9) = Ap.transpose() * cAp + kd;
  if (has_left) {
    B.block<3, 3>(0, 0) = cm;
    B.block<3, 3>(0, 3) = cAl;
    B.block<3, 3>(0, 6) = -cm;
    B.block<3, 3>(0, 9) = -cAp;
    B.block<3, 3>(3, 3) = Al.transpose() * cAl + kd;
    B.block<3, 3>(3, 6) = -cAl.transpose();
    B.block<3, 3>(3, 9) = -Al.transpose() * cAp - kd;
  }
  for (int bi = 0; bi < 4; ++bi)
    for (int bj = 0; bj < bi; ++bj) B.block<3, 3>(3 * bi, 3 * bj) = B.block<3, 3>(3 * bj, 3 * bi).transpose();
  if (C) *C = beta * B;
  // Geometric term Σ_i λ_i ∂²Δx_i/∂φ∂φ, λ = c Δx.
  const Vec3 lam = e.c.cwiseProduct(dx);
  for (int a = 0; a < 3; ++a)
    for (int b = a; b < 3; ++b) {
      const double gp = lam.dot(dp.ddR[a][b] * e.eta_right);
      B(9 + a, 9 + b) += gp;
      if (b != a) B(9 + b, 9 + a) += gp;
      if (has_left) {
        const double gl = lam.dot(dl.ddR[a][b] * e.eta_left);
        B(3 + a, 3 + b) -= gl;
        if (b != a) B(3 + b, 3 + a) -= gl;
      }
    }
  K = B;
}

void sde_matrix(const Sde& e, const Vec3& cl, const Vec3& cr, double beta, const Vec6& ql,
                const Vec6& qp, double ck, double cd, Mat12& S, Mat12* K) {
  Mat12 base, geo;
  sde_parts(e, cl, cr, ql, qp, base, geo);
  S.noalias() += (ck + cd * beta) * base + ck * geo;
  if (K) K->noalias() += base + geo;
}

}  // namespace rfem
