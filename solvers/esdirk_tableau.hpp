#pragma once
// The pieces of the ESDIRK integrator (solvers/esdirk.cpp) that are not its step loop: the
// Butcher tableau from SUNDIALS ARKODE with its checks and derived coefficients, the vector work
// on the team (norms, combinations of the stages) and the Hermite bases of the dense output.
#include <string>
#include <vector>

#include "../core/types.hpp"

namespace rfem::esdirk {

/// The parts a reduction over the team keeps (a team is never larger).
constexpr int kMaxTeam = 64;

struct Tableau {
  int s = 0, order = 0, embedded_order = 0;
  MatX A, AA;         ///< A and A²
  VecX b, c, eq, ev;  ///< weights, nodes, error coefficients of q (((b−d)ᵀA)) and v (b − d)
  double gamma = 0.0;
};

/// ARKODE's DIRK table `name` (without the ARKODE_ prefix); std::invalid_argument unless it is an
/// embedded, stiffly accurate ESDIRK method with an explicit first stage.
Tableau load_tableau(const std::string& name);

/// Weighted max norm of a stage increment δα as the change it makes in [Q; V] = [(hγ)² δα; hγ δα];
/// NaN or inf if δα is not finite (then no test passes). Two vectorised reductions: a running
/// std::max over the unknowns was the integrator's largest serial cost.
/// On the team (solvers/team_parts.hpp): a maximum is the same whatever the parts. With `update`,
/// also *update −= da in the same pass (one region fewer per Newton iteration; the caller discards
/// the update when the result is not finite).
double wmax_increment(const VecX& da, double hg, const VecX& w, int team, VecX* update = nullptr);

/// out_k = x_k + Σ_{j<m} c_j y_j for two outputs over the same y's, in one pass over memory (blocks
/// that stay in cache); each element sums in the order of the vector operations it replaces (same
/// bits).
void combine(VecX& out1, const VecX& x1, const double* c1, VecX& out2, const VecX& x2, const double* c2,
             const std::vector<VecX>& y, int m, int team);

/// Weighted RMS norm over [x_q; x_v] with weights w (size 2u).
double wrms(const VecX& xq, const VecX& xv, const VecX& w);

/// Quintic Hermite basis on θ ∈ [0, 1] (values, first and second θ-derivatives) for y0, h y0',
/// h² y0'', y1, h y1', h² y1''.
void hermite5(double t, double H[6], double dH[6], double ddH[6]);

/// Cubic Hermite of an integral E with rate P.
double hermite3(double t, double h, double E0, double P0, double E1, double P1);

}  // namespace rfem::esdirk
