#include "rfem/studies/linearize.hpp"

#include <Eigen/Cholesky>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "rfem/results/reader.hpp"
#include "rfem/results/writer.hpp"
#include "rfem/studies/simulation.hpp"

namespace rfem {

namespace {
// Central differences in q and q̇ at h and 2h, extrapolated (Richardson): truncation O(h⁴). The
// residual is smooth there (trigonometric in the rotations, quadratic in the rates) but computed
// from positions of the model's size, so round-off puts ~ε L / h into a column; h = 1e-5 [m, rad,
// m/s, rad/s] keeps both near 1e-10 of it (Kane's beam: its frequencies within 3e-10 of rfem modes;
// 1e-6 and 1e-4 measured alike, 1e-3 3e-10 from truncation).
constexpr double kStep = 1e-5;

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
  lin.M.resize(N, N);
  lin.D.resize(N, N);
  lin.K.resize(N, N);
  lin.Cq.resize(P, N);
  lin.Cv.resize(P, N);
  lin.Ca.resize(P, N);
  VecX q = q0, v = v0, a = a0, rp, rm, yp, ym;
  // Richardson's extrapolation of central differences at h and 2h: truncation O(h⁴).
  VecX r2p, r2m, y2p, y2m;
  auto derivative = [&](VecX& x, Eigen::Index i, bool rates, MatX& J, MatX& C) {
    const double x0 = x[i];
    auto at = [&](double dx, VecX& r, VecX& y) {
      x[i] = x0 + dx;
      if (rates) f(q0, x, a0, r, y);
      else f(x, v0, a0, r, y);
    };
    at(kStep, rp, yp);
    at(-kStep, rm, ym);
    at(2 * kStep, r2p, y2p);
    at(-2 * kStep, r2m, y2m);
    x[i] = x0;
    J.col(i) = (8 * (rp - rm) - (r2p - r2m)) / (12 * kStep);
    C.col(i) = (8 * (yp - ym) - (y2p - y2m)) / (12 * kStep);
  };
  for (Eigen::Index i = 0; i < N; ++i) {
    derivative(q, i, false, lin.K, lin.Cq);
    derivative(v, i, true, lin.D, lin.Cv);
    a[i] = a0[i] + 1.0;  // (linear in q̈: one-sided and exact up to round-off)
    f(q0, v0, a, rp, yp);
    a[i] = a0[i];
    lin.M.col(i) = rp - r0;
    lin.Ca.col(i) = yp - y0;
  }
  lin.B = MatX::Zero(N, static_cast<Eigen::Index>(free_rows.size()));
  lin.u0.resize(static_cast<Eigen::Index>(free_rows.size()));
  for (size_t k = 0; k < free_rows.size(); ++k) {
    lin.B(free_rows[k], static_cast<Eigen::Index>(k)) = 1.0;
    lin.u0[static_cast<Eigen::Index>(k)] = r0[free_rows[k]];
  }
  lin.q0 = q0;
  lin.v0 = v0;
  lin.a0 = a0;
  lin.y0 = y0;
  double scale = 0.0, worst = 0.0;
  for (Eigen::Index i = 0; i < rfe_rows; ++i) {
    worst = std::max(worst, std::abs(r0[i]));
    scale = std::max({scale, lin.K.col(i).cwiseAbs().maxCoeff() * 1e-3, lin.M.col(i).cwiseAbs().maxCoeff() * 9.81});
  }
  lin.imbalance = scale > 0 ? worst / scale : 0.0;
}

std::vector<std::string> LinearModel::first_order_states() const {
  std::vector<std::string> x = states;
  for (const auto& s : states) x.push_back("d/dt " + s);
  return x;
}

void LinearModel::state_space(MatX& A, MatX& Bs, MatX& C, MatX& Ds) const {
  const Eigen::Index N = M.rows();
  const Eigen::LLT<MatX> llt(M);
  if (llt.info() != Eigen::Success) throw std::runtime_error("linear model: the mass matrix is not positive definite");
  const MatX MK = llt.solve(K), MD = llt.solve(D), MB = llt.solve(B);
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

void write_linear(ResultsWriter& file, const LinearModel& lin) {
  MatX A, Bs, C, Ds;
  lin.state_space(A, Bs, C, Ds);
  const std::vector<std::string> x = lin.first_order_states();
  auto put = [&](const std::string& name, const MatX& m, const std::vector<std::string>& rows, const std::vector<std::string>& cols,
                 const std::string& description) {
    file.write_table("linear/" + name, table_of(m), cols, std::vector<std::string>(cols.size(), ""), description);
    file.write_attribute("linear/" + name, "rows", rows);
  };
  put("M", lin.M, lin.states, lin.states, "mass: M δq̈ + D δq̇ + K δq = B δu");
  put("D", lin.D, lin.states, lin.states, "damping (sdes, drives, PD kd, gyroscopic)");
  put("K", lin.K, lin.states, lin.states, "stiffness (elastic, geometric, gravity, centrifugal, PD kp)");
  const bool inputs = !lin.inputs.empty();  // (a model with every joint prescribed has none)
  if (inputs) put("B", lin.B, lin.states, lin.inputs, "input matrix: a torque (force) added at each free joint");
  put("Cq", lin.Cq, lin.outputs, lin.states, "outputs: δy = Cq δq + Cv δq̇ + Ca δq̈");
  put("Cv", lin.Cv, lin.outputs, lin.states, "outputs' rate part");
  put("Ca", lin.Ca, lin.outputs, lin.states, "outputs' acceleration part");
  put("A", A, x, x, "first order: ẋ = A x + Bs u, x = (δq, δq̇)");
  if (inputs) put("Bs", Bs, x, lin.inputs, "first order input matrix");
  put("C", C, lin.outputs, x, "first order: y = C x + Ds u");
  if (inputs) put("Ds", Ds, lin.outputs, lin.inputs, "first order feed-through");
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
  LinearModel lin = sim.linearize(rq.equilibrium);
  sim.finish(RunStatus::interrupted(0));
  return lin;
}

}  // namespace rfem
