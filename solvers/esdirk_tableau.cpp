#include "esdirk_tableau.hpp"

#include <cstdio>  // before arkode_butcher.h, which uses FILE without including it

#include <arkode/arkode_butcher_dirk.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "team_parts.hpp"

namespace rfem::esdirk {

Tableau load_tableau(const std::string& name) {
  ARKodeButcherTable B = ARKodeButcherTable_LoadDIRKByName(("ARKODE_" + name).c_str());
  if (!B) throw std::invalid_argument("unknown ESDIRK table '" + name + "'");
  Tableau T;
  T.s = B->stages;
  T.order = B->q;
  T.embedded_order = B->p;
  T.A.resize(T.s, T.s);
  T.b.resize(T.s);
  T.c.resize(T.s);
  VecX d(T.s);
  for (int i = 0; i < T.s; ++i) {
    for (int j = 0; j < T.s; ++j) T.A(i, j) = B->A[i][j];
    T.b[i] = B->b[i];
    T.c[i] = B->c[i];
    d[i] = B->d ? B->d[i] : NAN;
  }
  ARKodeButcherTable_Free(B);
  T.gamma = T.A(T.s - 1, T.s - 1);
  bool ok = T.s >= 2 && T.A(0, 0) == 0.0 && d.allFinite();
  for (int i = 0; i < T.s && ok; ++i) {
    for (int j = i + 1; j < T.s; ++j) ok &= T.A(i, j) == 0.0;
    if (i > 0) ok &= std::abs(T.A(i, i) - T.gamma) < 1e-14;
    ok &= std::abs(T.A(T.s - 1, i) - T.b[i]) < 1e-14;
  }
  if (!ok)
    throw std::invalid_argument("table '" + name + "' is not an embedded, stiffly accurate ESDIRK method " +
                                "with an explicit first stage");
  T.AA = T.A * T.A;
  T.ev = T.b - d;
  T.eq = T.A.transpose() * T.ev;
  return T;
}

double wmax_increment(const VecX& da, double hg, const VecX& w, int team, VecX* update) {
  const long u = da.size();
  if (u == 0) return 0.0;
  double part[2][kMaxTeam] = {};
  team = std::min(team, kMaxTeam);
  for_team_parts(u, team, [&](long b, long e) {
    const int t = team > 1 ? omp_get_thread_num() : 0;
    if (e <= b) return;
    const long n = e - b;
    part[0][t] = (da.segment(b, n).array() * w.segment(b, n).array()).abs().maxCoeff<Eigen::PropagateNaN>();
    part[1][t] = (da.segment(b, n).array() * w.segment(u + b, n).array()).abs().maxCoeff<Eigen::PropagateNaN>();
    if (update) update->segment(b, n) -= da.segment(b, n);
  });
  double mq = 0.0, mv = 0.0;
  for (int t = 0; t < team; ++t) {
    if (std::isnan(part[0][t]) || std::isnan(part[1][t])) return part[0][t] + part[1][t];
    mq = std::max(mq, part[0][t]);  // (std::max would drop a NaN second argument: tested above)
    mv = std::max(mv, part[1][t]);
  }
  return std::max(hg * hg * mq, hg * mv);
}

void combine(VecX& out1, const VecX& x1, const double* c1, VecX& out2, const VecX& x2, const double* c2,
             const std::vector<VecX>& y, int m, int team) {
  for_team_parts(x1.size(), team, [&](long begin, long end) {
    constexpr long kBlock = 512;
    for (long b0 = begin; b0 < end; b0 += kBlock) {
      const long n = std::min(kBlock, end - b0);
      auto o1 = out1.segment(b0, n), o2 = out2.segment(b0, n);
      o1 = x1.segment(b0, n);
      o2 = x2.segment(b0, n);
      for (int j = 0; j < m; ++j) {
        o1 += c1[j] * y[j].segment(b0, n);
        o2 += c2[j] * y[j].segment(b0, n);
      }
    }
  });
}

double wrms(const VecX& xq, const VecX& xv, const VecX& w) {
  const int u = static_cast<int>(xq.size());
  double s = 0.0;
  for (int i = 0; i < u; ++i) {
    const double a = xq[i] * w[i], b = xv[i] * w[u + i];
    s += a * a + b * b;
  }
  return std::sqrt(s / std::max(1, 2 * u));
}

void hermite5(double t, double H[6], double dH[6], double ddH[6]) {
  const double t2 = t * t, t3 = t2 * t, t4 = t3 * t, t5 = t4 * t;
  H[0] = 1 - 10 * t3 + 15 * t4 - 6 * t5;
  H[1] = t - 6 * t3 + 8 * t4 - 3 * t5;
  H[2] = 0.5 * t2 - 1.5 * t3 + 1.5 * t4 - 0.5 * t5;
  H[3] = 10 * t3 - 15 * t4 + 6 * t5;
  H[4] = -4 * t3 + 7 * t4 - 3 * t5;
  H[5] = 0.5 * t3 - t4 + 0.5 * t5;
  dH[0] = -30 * t2 + 60 * t3 - 30 * t4;
  dH[1] = 1 - 18 * t2 + 32 * t3 - 15 * t4;
  dH[2] = t - 4.5 * t2 + 6 * t3 - 2.5 * t4;
  dH[3] = 30 * t2 - 60 * t3 + 30 * t4;
  dH[4] = -12 * t2 + 28 * t3 - 15 * t4;
  dH[5] = 1.5 * t2 - 4 * t3 + 2.5 * t4;
  ddH[0] = -60 * t + 180 * t2 - 120 * t3;
  ddH[1] = -36 * t + 96 * t2 - 60 * t3;
  ddH[2] = 1 - 9 * t + 18 * t2 - 10 * t3;
  ddH[3] = 60 * t - 180 * t2 + 120 * t3;
  ddH[4] = -24 * t + 84 * t2 - 60 * t3;
  ddH[5] = 3 * t - 12 * t2 + 10 * t3;
}

double hermite3(double t, double h, double E0, double P0, double E1, double P1) {
  const double t2 = t * t, t3 = t2 * t;
  return (2 * t3 - 3 * t2 + 1) * E0 + (t3 - 2 * t2 + t) * h * P0 + (-2 * t3 + 3 * t2) * E1 + (t3 - t2) * h * P1;
}

}  // namespace rfem::esdirk
