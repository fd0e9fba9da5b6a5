#include "linearize.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseLU>
// (GCC 12 sees a use after free inside Spectra's Hessenberg eigenvectors, which are not computed here)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuse-after-free"
#include <Spectra/GenEigsRealShiftSolver.h>
#pragma GCC diagnostic pop
#include <algorithm>
#include <cstdio>
#include <limits>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "../core/positions.hpp"
#include "../results/reader.hpp"
#include "../results/writer.hpp"
#include "../simulation/sensors.hpp"
#include "../simulation/simulation.hpp"

namespace rfem {

namespace {

Table table_of(const MatX& m) {
  Table t{m.rows(), m.cols(), std::vector<double>(static_cast<size_t>(m.size()))};
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) t.data[static_cast<size_t>(r * m.cols() + c)] = m(r, c);
  return t;
}
}  // namespace

void linearize_about(const LinearEvaluation& f, const VecX& q0, const VecX& v0, const VecX& a0,
                     const std::vector<int>& free_rows, int rfe_rows, LinearModel& lin) {
  const Eigen::Index N = q0.size();
  if (v0.size() != N || a0.size() != N) throw std::invalid_argument("linearize: q, v and a of different sizes");
  VecX r0, y0;
  f(q0, v0, a0, r0, y0);
  const Eigen::Index P = y0.size();
  MatX M(N, N), D(N, N), K(N, N);
  lin.Cq.resize(P, N);
  lin.Cv.resize(P, N);
  lin.Ca.resize(P, N);
  VecX q = q0, v = v0, a = a0, rp, yp, dr, dy;
  auto derivative = [&](VecX& x, Eigen::Index i, bool rates, MatX& J, MatX& C) {
    const double x0 = x[i];
    richardson_difference([&](double dx, VecX& r, VecX& y) {
      x[i] = x0 + dx;
      if (rates) f(q0, x, a0, r, y);
      else f(x, v0, a0, r, y);
    }, dr, dy);
    x[i] = x0;
    J.col(i) = dr;
    C.col(i) = dy;
  };
  for (Eigen::Index i = 0; i < N; ++i) {
    derivative(q, i, false, K, lin.Cq);
    derivative(v, i, true, D, lin.Cv);
    a[i] = a0[i] + 1.0;  // (linear in q̈: one-sided and exact up to round-off)
    f(q0, v0, a, rp, yp);
    a[i] = a0[i];
    M.col(i) = rp - r0;
    lin.Ca.col(i) = yp - y0;
  }
  lin.M = M.sparseView(1.0, 0.0);  // (exact zeros only)
  lin.D = D.sparseView(1.0, 0.0);
  lin.K = K.sparseView(1.0, 0.0);
  lin.evaluations = static_cast<int>(9 * N + 1);
  set_operating_point(lin, q0, v0, a0, r0, y0, free_rows, rfe_rows);
}

void linearize_sparse(EquationsOfMotion& eq, double t, const LinearEvaluation& f, const OutputEvaluation& g,
                      const VecX& q0, const VecX& v0, const VecX& a0, const std::vector<int>& free_rows, int rfe_rows,
                      LinearModel& lin) {
  const Model& md = eq.model();
  const Eigen::Index N = q0.size();
  const VecX qf = eq.full_coordinates(t, q0.data(), 0), vf = eq.full_coordinates(t, v0.data(), 1),
             af = eq.full_coordinates(t, a0.data(), 2);
  const EquationsJacobian J = equations_jacobian(md, eq.inputs(), eq.terms(), t, qf, vf, af);
  const int U = static_cast<int>(J.K.rows());
  const Reduction* red = eq.reduction().get();
  const SparseMat P = red ? red->projector(U - md.flexible_dofs()) : SparseMat();
  auto reduce = [&](const SparseMat& S) { return red ? SparseMat(SparseMat(P.transpose()) * S * P) : S; };
  lin.K = reduce(J.K);
  lin.D = reduce(J.D);
  lin.M = reduce(J.M);
  // Outputs y(q, v, a, τ) column by column (cheap: no equations), τ's part through the torque rows.
  VecX qw = qf, vw = vf, aw = af, tw = J.tau0, y0, y1, unused;
  g(qw, vw, aw, tw, y0);
  const Eigen::Index Pn = y0.size();
  auto slope = [&](VecX& x, Eigen::Index i) {
    const double x0 = x[i];
    VecX dy;
    richardson_difference([&](double d, VecX& y, VecX&) { x[i] = x0 + d, g(qw, vw, aw, tw, y); }, dy, unused);
    x[i] = x0;
    return dy;
  };
  MatX dy_dtau(Pn, md.m()), Cq(Pn, U), Cv(Pn, U), Ca(Pn, U);
  for (int j = 0; j < md.m(); ++j) dy_dtau.col(j) = slope(tw, j);
  for (int c = 0; c < U; ++c) {
    const int k = J.coords[static_cast<size_t>(c)];
    Cq.col(c) = slope(qw, k);
    Cv.col(c) = slope(vw, k);
    aw[k] += 1.0;  // (linear in q̈)
    g(qw, vw, aw, tw, y1);
    aw[k] = af[k];
    Ca.col(c) = y1 - y0;
  }
  Cq += dy_dtau * J.tau_q;
  Cv += dy_dtau * J.tau_v;
  Ca += dy_dtau * J.tau_a;
  lin.Cq = red ? MatX(Cq * P) : Cq;
  lin.Cv = red ? MatX(Cv * P) : Cv;
  lin.Ca = red ? MatX(Ca * P) : Ca;
  VecX r0, yu0;
  f(q0, v0, a0, r0, yu0);
  set_operating_point(lin, q0, v0, a0, r0, yu0, free_rows, rfe_rows);
  lin.evaluations = J.evaluations + 1;
  // The check: directional differences of the equations themselves along a fixed direction that
  // touches every unknown, of the columns' size (what a wrong sparsity pattern would miss shows as
  // a row's mismatch).
  VecX w(N);
  for (Eigen::Index i = 0; i < N; ++i) w[i] = std::sin(1.0 + 0.7 * static_cast<double>(i));  // (fixed: no random stream)
  const char* names[3] = {"K", "D", "M"};
  const SparseMat* Js[3] = {&lin.K, &lin.D, &lin.M};
  const MatX* Cs[3] = {&lin.Cq, &lin.Cv, &lin.Ca};
  for (int kind = 0; kind < 3; ++kind) {
    auto along = [&](double d, VecX& r, VecX& y) {
      VecX x[3] = {q0, v0, a0};
      x[kind] += d * w;
      f(x[0], x[1], x[2], r, y);
    };
    VecX dr, dy;
    if (kind < 2) {
      richardson_difference(along, dr, dy);
      lin.evaluations += 4;
    } else {
      along(1.0, dr, dy);
      dr -= r0;
      dy -= yu0;
      lin.evaluations += 1;
    }
    // The differences' round-off: ~1.5 ε |value| / h (Richardson's weights), ten times that.
    const double noise = 10 * std::numeric_limits<double>::epsilon() / (kind < 2 ? kLinearizationStep : 1.0);
    Eigen::Index row = 0, out_row = 0;
    const double bad = directional_mismatch(*Js[kind], w, dr, noise * r0.cwiseAbs(), &row);
    const double bad_y = directional_mismatch(Cs[kind]->sparseView(1.0, 0.0), w, dy, noise * yu0.cwiseAbs(), &out_row);
    // (Measured ≤ 2.5e-8 of a row: the differences' round-off; a missed entry shows at its size.)
    if (bad > 1e-6 || bad_y > 1e-6) {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.2g", std::max(bad, bad_y));
      const std::string where = bad >= bad_y ? "row " + lin.states[static_cast<size_t>(row)]
                                             : "output " + lin.outputs[static_cast<size_t>(out_row)];
      throw std::runtime_error(std::string("linearize: the sparse ") + names[kind] +
                               " differs from the equations' directional difference by " + buf + " of " + where +
                               "; --dense (Python dense=True) differences them column by column (please report this model)");
    }
  }
}

void set_operating_point(LinearModel& lin, const VecX& q0, const VecX& v0, const VecX& a0, const VecX& r0, const VecX& y0,
                         const std::vector<int>& free_rows, int rfe_rows) {
  const Eigen::Index N = q0.size();
  lin.B.resize(N, static_cast<Eigen::Index>(free_rows.size()));
  lin.B.setZero();
  lin.u0.resize(static_cast<Eigen::Index>(free_rows.size()));
  for (size_t k = 0; k < free_rows.size(); ++k) {
    lin.B.insert(free_rows[k], static_cast<Eigen::Index>(k)) = 1.0;
    lin.u0[static_cast<Eigen::Index>(k)] = r0[free_rows[k]];
  }
  lin.B.makeCompressed();
  lin.q0 = q0;
  lin.v0 = v0;
  lin.a0 = a0;
  lin.y0 = y0;
  // The rfe rows' residual against the largest elastic (K over 1 mm) or weight (M g) term of their columns.
  VecX colK = VecX::Zero(N), colM = VecX::Zero(N);
  for (Eigen::Index c = 0; c < N; ++c) {
    for (SparseMat::InnerIterator it(lin.K, c); it; ++it) colK[c] = std::max(colK[c], std::abs(it.value()));
    for (SparseMat::InnerIterator it(lin.M, c); it; ++it) colM[c] = std::max(colM[c], std::abs(it.value()));
  }
  double scale = 0.0, worst = 0.0;
  for (Eigen::Index i = 0; i < rfe_rows; ++i) {
    worst = std::max(worst, std::abs(r0[i]));
    scale = std::max({scale, colK[i] * 1e-3, colM[i] * 9.81});
  }
  lin.imbalance = scale > 0 ? worst / scale : 0.0;
}

double directional_mismatch(const SparseMat& J, const VecX& w, const VecX& dJw, const VecX& noise, Eigen::Index* row) {
  const VecX Jw = J * w;
  const VecX size = J.cwiseAbs() * w.cwiseAbs();
  const double floor = 1e-9 * size.maxCoeff();
  double worst = 0.0;
  for (Eigen::Index i = 0; i < Jw.size(); ++i) {
    const double e = std::abs(Jw[i] - dJw[i]) / (size[i] + floor + 1e6 * noise[i] + 1e-300);
    if (e > worst) {
      worst = e;
      if (row) *row = i;
    }
  }
  return worst;
}

std::vector<std::string> LinearModel::first_order_states() const {
  std::vector<std::string> x = states;
  for (const auto& s : states) x.push_back("d/dt " + s);
  return x;
}

void LinearModel::descriptor(SparseMat& E, SparseMat& A, SparseMat& Bd, SparseMat& C) const {
  const Eigen::Index N = M.rows(), P = Cq.rows(), m = B.cols();
  std::vector<Eigen::Triplet<double>> e, a, b, c;
  for (Eigen::Index i = 0; i < 2 * N; ++i) e.emplace_back(i, i, 1.0);
  for (Eigen::Index i = 0; i < 2 * N; ++i) a.emplace_back(i, N + i, 1.0);  // q' = v, v' = a
  const SparseMat* blocks[3] = {&K, &D, &M};
  for (int k = 0; k < 3; ++k)
    for (Eigen::Index col = 0; col < N; ++col)
      for (SparseMat::InnerIterator it(*blocks[k], col); it; ++it) a.emplace_back(2 * N + it.row(), k * N + col, -it.value());
  for (Eigen::Index col = 0; col < m; ++col)
    for (SparseMat::InnerIterator it(B, col); it; ++it) b.emplace_back(2 * N + it.row(), col, it.value());
  const MatX* outs[3] = {&Cq, &Cv, &Ca};
  for (int k = 0; k < 3; ++k)
    for (Eigen::Index i = 0; i < P; ++i)
      for (Eigen::Index j = 0; j < N; ++j)
        if ((*outs[k])(i, j) != 0.0) c.emplace_back(i, k * N + j, (*outs[k])(i, j));
  E.resize(3 * N, 3 * N);
  E.setFromTriplets(e.begin(), e.end());
  A.resize(3 * N, 3 * N);
  A.setFromTriplets(a.begin(), a.end());
  Bd.resize(3 * N, m);
  Bd.setFromTriplets(b.begin(), b.end());
  C.resize(P, 3 * N);
  C.setFromTriplets(c.begin(), c.end());
}

void LinearModel::state_space(MatX& A, MatX& Bs, MatX& C, MatX& Ds) const {
  const Eigen::Index N = M.rows();
  if (N > kMaxDenseStates)
    throw std::invalid_argument("state_space: " + std::to_string(N) + " states make a dense A of " + std::to_string(2 * N) +
                                "² values; above " + std::to_string(kMaxDenseStates) +
                                " use M, D, K (sparse) or a reduced link (modes = m)");
  const Eigen::SimplicialLDLT<SparseMat> ldlt(M);
  if (ldlt.info() != Eigen::Success || (ldlt.vectorD().array() <= 0).any())
    throw std::runtime_error("linear model: the mass matrix is not positive definite");
  const MatX MK = ldlt.solve(MatX(K)), MD = ldlt.solve(MatX(D)), MB = ldlt.solve(MatX(B));
  A = MatX::Zero(2 * N, 2 * N);
  A.topRightCorner(N, N).setIdentity();
  A.bottomLeftCorner(N, N) = -MK;
  A.bottomRightCorner(N, N) = -MD;
  Bs = MatX::Zero(2 * N, B.cols());
  Bs.bottomRows(N) = MB;
  C.resize(Cq.rows(), 2 * N);
  C.leftCols(N) = Cq - Ca * MK;  // δq̈ = M⁻¹ (B u − K δq − D δq̇)
  C.rightCols(N) = Cv - Ca * MD;
  Ds = Ca * MB;
}

namespace {
// Dense eigenvalues of A only for tiny models: QR's absolute error ε‖A‖ (‖A‖ ~ the highest ω²)
// moves the lowest frequencies (~1e-5 relative at n = 100) and their real parts (1.5e-7 of a
// damping ratio of 0.004 at n = 12); shift-invert finds them to round-off.
constexpr Eigen::Index kDenseModes = 16;

// (A − σI)⁻¹ for A = [0 I; −M⁻¹K −M⁻¹D] from the sparse pencil: with y2 = x1 + σ y1,
// (K + σD + σ²M) y1 = −M x2 − (D + σM) x1 (Spectra's shift-solve operation).
class PencilShiftSolve {
 public:
  using Scalar = double;
  explicit PencilShiftSolve(const LinearModel& lin) : lin_(lin), n_(lin.M.rows()) {}
  Eigen::Index rows() const { return 2 * n_; }
  Eigen::Index cols() const { return 2 * n_; }
  void set_shift(double sigma) {
    sigma_ = sigma;
    const SparseMat Q = lin_.K + sigma * lin_.D + sigma * sigma * lin_.M;
    lu_.setPivotThreshold(0.01);  // (the diagonal unless it is 100× smaller than its column)
    lu_.compute(Q);
    if (lu_.info() != Eigen::Success) throw std::runtime_error("linear model modes: K + σD + σ²M is singular");
  }
  void perform_op(const double* x_in, double* y_out) const {
    const Eigen::Map<const VecX> x1(x_in, n_), x2(x_in + n_, n_);
    Eigen::Map<VecX> y1(y_out, n_), y2(y_out + n_, n_);
    const VecX rhs = -(lin_.M * x2) - lin_.D * x1 - sigma_ * (lin_.M * x1);
    y1 = lu_.solve(rhs);
    y2 = x1 + sigma_ * y1;
  }

 private:
  const LinearModel& lin_;
  Eigen::Index n_;
  double sigma_ = 0.0;
  // The states' own order: every link's rfes in a chain, then what borders them (carrying rfes,
  // modal coordinates, free joints) — no fill beyond the chains (COLAMD's order filled 40 M entries
  // at 24 000 states, with the free joints' dense rows).
  Eigen::SparseLU<SparseMat, Eigen::NaturalOrdering<int>> lu_;
};
}  // namespace

std::vector<std::pair<double, double>> linear_modes(const LinearModel& lin, int count) {
  if (count < 1) throw std::invalid_argument("count: must be 1 or more (got " + std::to_string(count) + ")");
  const Eigen::Index N = lin.M.rows();
  Eigen::VectorXcd ev;
  if (N <= kDenseModes) {
    MatX A, B, C, D;
    lin.state_space(A, B, C, D);
    ev = Eigen::EigenSolver<MatX>(A, false).eigenvalues();
  } else {  // the eigenvalues nearest a small negative shift: the lowest modes, the rigid ones' zeros
    PencilShiftSolve op(lin);
    const Eigen::Index nev = std::min<Eigen::Index>(2 * count + 6, 2 * N - 3);
    Spectra::GenEigsRealShiftSolver<PencilShiftSolve> es(op, nev, std::min<Eigen::Index>(2 * nev + 1, 2 * N), -0.1);
    es.init();
    // A free joint's rigid motion is a double zero of A (a Jordan block: Arnoldi converges to it to
    // only √ε); the oscillating modes converge all the same, and eigenvalues() returns the
    // converged ones: enough unless fewer than `count` of those oscillate.
    es.compute(Spectra::SortRule::LargestMagn, 1000, 1e-12);
    ev = es.eigenvalues();
    const long pairs = (ev.array().imag() > 0).count();
    if (es.info() != Spectra::CompInfo::Successful && pairs < std::min<long>(count, N - 1))
      throw std::runtime_error("linear model modes: the eigensolver did not converge (" + std::to_string(pairs) + " of " +
                               std::to_string(count) + " modes)");
  }
  std::vector<std::pair<double, double>> modes;  // (f [Hz], ζ) of each pair with ω > 0
  for (Eigen::Index i = 0; i < ev.size(); ++i)
    if (ev[i].imag() > 0) modes.emplace_back(std::abs(ev[i]) / (2 * M_PI), -ev[i].real() / std::abs(ev[i]));
  std::sort(modes.begin(), modes.end());
  if (static_cast<int>(modes.size()) > count) modes.resize(static_cast<size_t>(count));
  return modes;
}

void write_linear(ResultsWriter& file, const LinearModel& lin) {
  const bool first_order = lin.M.rows() <= LinearModel::kFileDenseStates;
  MatX A, Bs, C, Ds;
  if (first_order) lin.state_space(A, Bs, C, Ds);
  const std::vector<std::string> x = lin.first_order_states();
  auto put = [&](const std::string& name, const MatX& m, const std::vector<std::string>& rows, const std::vector<std::string>& cols,
                 const std::string& description) {
    file.write_table("linear/" + name, table_of(m), cols, std::vector<std::string>(cols.size(), ""), description);
    file.write_attribute("linear/" + name, "rows", rows);
  };
  // Sparse: (row, column, value), 0-based — scipy.sparse.coo_matrix((v, (r, c))), MATLAB sparse(r+1, c+1, v, …).
  auto put_sparse = [&](const std::string& name, const SparseMat& m, const std::vector<std::string>& rows,
                        const std::vector<std::string>& cols, const std::string& description) {
    Table t{static_cast<long>(m.nonZeros()), 3, {}};
    t.data.reserve(static_cast<size_t>(3 * m.nonZeros()));
    for (Eigen::Index c = 0; c < m.outerSize(); ++c)
      for (SparseMat::InnerIterator it(m, c); it; ++it)
        t.data.insert(t.data.end(), {static_cast<double>(it.row()), static_cast<double>(it.col()), it.value()});
    t.rows = static_cast<long>(t.data.size() / 3);
    file.write_table("linear/" + name, t, {"row", "column", "value"}, {"", "", ""}, description + " (sparse: 0-based row, column, value)");
    file.write_attribute("linear/" + name, "rows", rows);
    file.write_attribute("linear/" + name, "matrix_columns", cols);
  };
  put_sparse("M", lin.M, lin.states, lin.states, "mass: M δq̈ + D δq̇ + K δq = B δu");
  put_sparse("D", lin.D, lin.states, lin.states, "damping (sdes, drives, PD kd, gyroscopic)");
  put_sparse("K", lin.K, lin.states, lin.states, "stiffness (elastic, geometric, gravity, centrifugal, PD kp)");
  const bool inputs = !lin.inputs.empty();  // (a model with every joint prescribed has none)
  if (inputs) put_sparse("B", lin.B, lin.states, lin.inputs, "input matrix: a torque (force) added at each free joint");
  put("Cq", lin.Cq, lin.outputs, lin.states, "outputs: δy = Cq δq + Cv δq̇ + Ca δq̈");
  put("Cv", lin.Cv, lin.outputs, lin.states, "outputs' rate part");
  put("Ca", lin.Ca, lin.outputs, lin.states, "outputs' acceleration part");
  if (first_order) {
    put("A", A, x, x, "first order: ẋ = A x + Bs u, x = (δq, δq̇)");
    if (inputs) put("Bs", Bs, x, lin.inputs, "first order input matrix");
    put("C", C, lin.outputs, x, "first order: y = C x + Ds u");
    if (inputs) put("Ds", Ds, lin.outputs, lin.inputs, "first order feed-through");
  }
  MatX op(3, lin.q0.size());
  op << lin.q0.transpose(), lin.v0.transpose(), lin.a0.transpose();
  put("operating_point", op, {"q", "v", "a"}, lin.states, "the state linearised about (unknowns)");
  put("y0", lin.y0.transpose(), {"y0"}, lin.outputs, "the outputs there");
  if (inputs)
    file.write_table("linear/u0", table_of(lin.u0.transpose()), lin.inputs, std::vector<std::string>(lin.inputs.size(), ""),
                   "the inputs there: what holds the state (the residual at the free joints)");
  std::ostringstream t;
  t.precision(17);
  t << lin.t;
  file.write_attribute("linear", "t", t.str());
  file.write_attribute("linear", "about", lin.equilibrium ? "equilibrium" : "state");
  file.write_attribute("linear", "states", lin.states);
  file.write_attribute("linear", "inputs", lin.inputs.empty() ? std::vector<std::string>{"(none)"} : lin.inputs);
  file.write_attribute("linear", "outputs", lin.outputs);
  file.write_attribute("linear", "output_units", lin.output_units);
  file.write_attribute("linear", "first_order",
                       first_order ? "A, Bs, C, Ds" : "not written above " + std::to_string(LinearModel::kFileDenseStates) +
                                                          " states: E x' = [0 I; -K -D] x + [0; B] u, E = [I 0; 0 M]");
}

LinearModel linearize(Simulation& sim, bool equilibrium, bool dense) {
  const IntegratorState x = sim.integrator_state();
  const Model& md = sim.model();
  EquationsOfMotion& eq = sim.equations();
  SensorBank* sensors = sim.sensors();
  const int N = eq.unknowns();
  LinearModel lin;
  lin.t = x.t;
  lin.equilibrium = equilibrium;
  const std::vector<std::string> names = sim.coordinate_names();
  lin.states = eq.unknown_names(names);
  std::vector<int> free_rows;
  for (int j = 0; j < md.m(); ++j)
    if (eq.base_col()[j] >= 0) {
      lin.inputs.push_back(md.joints[j].name);
      free_rows.push_back(eq.base_col()[j]);
    }
  for (const MountedLink& L : md.links)
    for (const char* c : {"tip_u1", "tip_u2", "tip_theta"}) {
      lin.outputs.push_back(L.name + "/" + c);
      lin.output_units.push_back(c == std::string("tip_theta") ? "rad" : "m");
    }
  for (const Joint& J : md.joints) {
    const bool turns = J.type == JointType::Revolute;
    for (const char* c : {"q", "v", "tau"}) lin.outputs.push_back(J.name + "/" + c);
    lin.output_units.insert(lin.output_units.end(), {turns ? "rad" : "m", turns ? "rad/s" : "m/s", turns ? "N m" : "N"});
  }
  if (sensors) {
    const auto c = sensors->columns(), u = sensors->units();
    lin.outputs.insert(lin.outputs.end(), c.begin(), c.end());
    lin.output_units.insert(lin.output_units.end(), u.begin(), u.end());
  }
  // The outputs at full coordinates and joint torques.
  std::vector<double> out;
  const OutputEvaluation outputs = [&](const VecX& q, const VecX& v, const VecX& a, const VecX& tau, VecX& y) {
    out.clear();
    for (size_t l = 0; l < md.links.size(); ++l) {
      const Vec3 d = tip_deflection(md, static_cast<int>(l), q);
      out.insert(out.end(), {d[0], d[1], d[2]});
    }
    for (int j = 0; j < md.m(); ++j) out.insert(out.end(), {q[md.joint_index(j)], v[md.joint_index(j)], tau[j]});
    if (sensors) sensors->read(q, v, a, tau, out, -1);  // (exact: no noise, no quantisation)
    y = Eigen::Map<const VecX>(out.data(), static_cast<Eigen::Index>(out.size()));
  };
  // The equations the integrators solve, over the (reduced) unknowns.
  const LinearEvaluation f = [&](const VecX& qu, const VecX& vu, const VecX& au, VecX& r, VecX& y) {
    r.resize(N);
    eq.residual(x.t, qu.data(), vu.data(), au.data(), r.data());
    outputs(eq.full_coordinates(x.t, qu.data(), 0), eq.full_coordinates(x.t, vu.data(), 1),
            eq.full_coordinates(x.t, au.data(), 2), eq.torques(x.t), y);
  };
  const VecX a0 = equilibrium ? VecX::Zero(N) : x.a;
  const int rfe_rows = N - static_cast<int>(free_rows.size());
  if (dense) linearize_about(f, x.q, x.v, a0, free_rows, rfe_rows, lin);
  else linearize_sparse(eq, x.t, f, outputs, x.q, x.v, a0, free_rows, rfe_rows, lin);
  return lin;
}

LinearModel linearize(const Case& cs, const LinearizeRequest& rq) {
  Case c = cs;
  c.sim.options.kind = IntegratorKind::Esdirk;  // (the equations are the integrators' same; only a stepped one starts here)
  c.has_simulation = true;  // (a linear model needs no [simulation]: its defaults, from t = 0)
  SimulationOptions o;
  o.n = rq.n;
  o.threads = rq.threads;
  o.state = rq.state;
  Simulation sim(c, std::move(o));
  if (sim.status().kind != RunStatus::Kind::Running) throw std::runtime_error("cannot linearise: " + sim.status().to_string());
  LinearModel lin = linearize(sim, rq.equilibrium, rq.dense);
  sim.finish(RunStatus::interrupted(0));
  return lin;
}

}  // namespace rfem
