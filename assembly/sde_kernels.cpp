#include "assembly/sde_kernels.hpp"

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
  Vec3 dx;
  Eigen::Matrix<double, 3, 12> J;
  displacement(e, cl, cr, ql, qp, rl, rp, dx, J);
  const bool has_left = e.left >= 0;
  const Vec3 dphi = qp.tail<3>() - (has_left ? ql.tail<3>() : Vec3::Zero().eval());
  Vec12 qdot;
  qdot << (has_left ? vl : Vec6::Zero().eval()), vp;
  const Vec3 dx_dot = J * qdot;
  const Vec3 dphi_dot = qdot.segment<3>(9) - qdot.segment<3>(3);
  const Vec3 lam = e.c.cwiseProduct(dx + beta * dx_dot);     // spring + damper force
  const Vec3 mu = e.k.cwiseProduct(dphi + beta * dphi_dot);  // spring + damper moment
  out.f = J.transpose() * lam;
  out.f.segment<3>(3) -= mu;
  out.f.segment<3>(9) += mu;
  if (!has_left) out.f.head<6>().setZero();
  out.V = 0.5 * dx.dot(e.c.cwiseProduct(dx)) + 0.5 * dphi.dot(e.k.cwiseProduct(dphi));
  out.P_d = beta * (dx_dot.dot(e.c.cwiseProduct(dx_dot)) + dphi_dot.dot(e.k.cwiseProduct(dphi_dot)));
}

void sde_matrix(const Sde& e, const Vec3& cl, const Vec3& cr, double beta, const Vec6& ql,
                const Vec6& qp, double ck, double cd, Mat12& S, Mat12* K) {
  SdeGeometry g;
  geometry(e, cl, cr, ql, qp, g, true);
  Mat12 base = g.J.transpose() * e.c.asDiagonal() * g.J;  // Jᵀ c J
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
  S.noalias() += (ck + cd * beta) * base;
  if (K) K->noalias() += base;
  // Geometric term Σ_i λ_i ∂²Δx_i/∂φ∂φ, λ = c Δx (the spring force turning with the rfe).
  const Vec3 lam = e.c.cwiseProduct(g.dx);
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const double gp = lam.dot(g.dp.ddR[a][b] * e.eta_right);
      S(9 + a, 9 + b) += ck * gp;
      if (K) (*K)(9 + a, 9 + b) += gp;
      if (e.left >= 0) {
        const double gl = lam.dot(g.dl.ddR[a][b] * e.eta_left);
        S(3 + a, 3 + b) -= ck * gl;
        if (K) (*K)(3 + a, 3 + b) -= gl;
      }
    }
}

}  // namespace rfem
