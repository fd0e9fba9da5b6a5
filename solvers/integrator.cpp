#include "solvers/integrator.hpp"

#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>

#include "solvers/mass_solve.hpp"
#include "solvers/newton_system.hpp"

namespace rfem {

namespace {

// Everything the IDA callbacks need.
struct Problem {
  const Model& model;
  const std::vector<JointInput>& inputs;
  const std::atomic<int>* stop;
  ForceTerms terms;
  std::vector<int> unknown;   ///< full index of each unknown coordinate
  std::vector<int> base_col;  ///< joint → column among the unknowns, −1 if prescribed
  std::unique_ptr<NewtonSystem> newton;
  std::vector<double> mass_values;  ///< scratch of the output accelerations' mass solve
  double cj_factor = 0.0;
  VecX q, v, a, F;            ///< full-coordinate scratch
  bool damped;

  Problem(const Model& m, const std::vector<JointInput>& in, const std::atomic<int>* s)
      : model(m), inputs(in), stop(s), damped(m.link.damping_beta > 0) {}
  int nu() const { return static_cast<int>(unknown.size()); }

  // Full q, v, a at time t from the unknowns' values and the laws of prescribed joints.
  void expand(double t, const double* y, const double* yp) {
    const int N = model.dof(), n6 = 6 * model.n(), u = nu();
    q.setZero(N);
    v.setZero(N);
    a.setZero(N);
    for (int i = 0; i < u; ++i) {
      q[unknown[i]] = y[i];
      v[unknown[i]] = y[u + i];
      if (yp) a[unknown[i]] = yp[u + i];
    }
    for (int j = 0; j < model.m(); ++j)
      if (inputs[j].prescribed()) {
        const MotionSample s = inputs[j].motion->at(t);
        q[n6 + j] = s.q;
        v[n6 + j] = s.qd;
        a[n6 + j] = s.qdd;
      }
  }
  // Joint torques: applied for force input, required (base rows of F) for kinematic input.
  VecX torques(double t) const {
    VecX tau(model.m());
    for (int j = 0; j < model.m(); ++j)
      tau[j] = inputs[j].prescribed() ? F[6 * model.n() + j] : inputs[j].torque->at(t);
    return tau;
  }
  double input_power(const VecX& tau) const { return tau.dot(v.tail(model.m())); }
};

int residual(sunrealtype t, N_Vector yv, N_Vector ypv, N_Vector rv, void* data) {
  auto& p = *static_cast<Problem*>(data);
  if (p.stop && p.stop->load()) return -1;  // unrecoverable: the caller reports the interruption
  const double *y = N_VGetArrayPointer(yv), *yp = N_VGetArrayPointer(ypv);
  double* r = N_VGetArrayPointer(rv);
  const int u = p.nu();
  try {
    p.expand(t, y, yp);
  } catch (const std::exception&) {
    return -1;
  }
  generalised_forces(p.model, p.q, p.v, p.a, p.terms, p.F);
  const VecX tau = p.torques(t);
  const int n6 = 6 * p.model.n();
  for (int i = 0; i < u; ++i) {
    r[i] = yp[i] - y[u + i];
    const int k = p.unknown[i];
    r[u + i] = p.F[k] - (k >= n6 ? tau[k - n6] : 0.0);
  }
  const double Pd = p.damped ? energies(p.model, p.q, p.v).dissipation_rate : 0.0;
  r[2 * u] = yp[2 * u] - Pd;
  r[2 * u + 1] = yp[2 * u + 1] - p.input_power(tau);
  for (int i = 0; i < 2 * u + 2; ++i)
    if (!std::isfinite(r[i])) return 1;  // recoverable: IDA retries with a smaller step
  return 0;
}

// IDA hands us c_j here: assemble S and K at the current y and factorise.
int jacobian(sunrealtype t, sunrealtype cj, N_Vector yv, N_Vector, N_Vector, SUNMatrix, void* data, N_Vector,
             N_Vector, N_Vector) {
  auto& p = *static_cast<Problem*>(data);
  p.expand(t, N_VGetArrayPointer(yv), nullptr);
  p.cj_factor = cj;
  return p.newton->setup(p.q, p.v, cj) ? 0 : 1;
}

int ls_solve(SUNLinearSolver ls, SUNMatrix, N_Vector xv, N_Vector bv, sunrealtype) {
  auto& p = *static_cast<Problem*>(ls->content);
  const double* b = N_VGetArrayPointer(bv);
  double* x = N_VGetArrayPointer(xv);
  const int u = p.nu();
  p.newton->solve(b, x);
  // Energy integrals: their coupling to y is left out (a modified Newton step for them).
  x[2 * u] = b[2 * u] / p.cj_factor;
  x[2 * u + 1] = b[2 * u + 1] / p.cj_factor;
  return 0;
}

SUNLinearSolver_Type ls_type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
int ls_setup(SUNLinearSolver, SUNMatrix) { return 0; }  // factorised in jacobian(), which knows c_j
int ls_free(SUNLinearSolver ls) {
  ls->content = nullptr;
  SUNLinSolFreeEmpty(ls);
  return 0;
}
// A placeholder matrix: IDA only needs to be able to zero and destroy it.
SUNMatrix_ID mat_id(SUNMatrix) { return SUNMATRIX_CUSTOM; }
int mat_zero(SUNMatrix) { return 0; }
void mat_destroy(SUNMatrix A) { SUNMatFreeEmpty(A); }

struct IdaHandles {
  SUNContext ctx = nullptr;
  void* ida = nullptr;
  N_Vector y = nullptr, yp = nullptr;
  SUNMatrix A = nullptr;
  SUNLinearSolver ls = nullptr;
  ~IdaHandles() {
    if (ida) IDAFree(&ida);
    if (ls) SUNLinSolFree(ls);
    if (A) SUNMatDestroy(A);
    if (y) N_VDestroy(y);
    if (yp) N_VDestroy(yp);
    if (ctx) SUNContext_Free(&ctx);
  }
};

// IDAGetReturnFlagName returns a malloc'ed string.
std::string flag_name(int flag) {
  char* s = IDAGetReturnFlagName(flag);
  std::string name(s ? s : "?");
  std::free(s);
  return name;
}

void check(int flag, const char* what) {
  if (flag < 0) throw std::runtime_error(std::string(what) + " failed: " + flag_name(flag));
}

// Accelerations of the unknowns from the equations of motion at state y:
// M_uu a_u = τ_u − F(q, v, a with a_u = 0). More accurate than IDA's interpolated y' (BDF2's
// derivative is first order), and what inverse dynamics needs for the required torques.
VecX consistent_accelerations(Problem& p, double t, const double* y) {
  const int u = p.nu(), n6 = 6 * p.model.n();
  p.expand(t, y, nullptr);
  generalised_forces(p.model, p.q, p.v, p.a, p.terms, p.F);
  const VecX tau = p.torques(t);
  VecX rhs(u);
  for (int i = 0; i < u; ++i) {
    const int k = p.unknown[i];
    rhs[i] = (k >= n6 ? tau[k - n6] : 0.0) - p.F[k];
  }
  if (!solve_mass(p.model, p.newton->pattern(), p.base_col, p.q, p.v, rhs, p.mass_values))
    throw std::runtime_error("the mass matrix is not positive definite at t = " + std::to_string(t));
  return rhs;
}

OutputSample sample(Problem& p, double t, const double* y) {
  const int u = p.nu();
  VecX yp = VecX::Zero(2 * u + 2);
  if (u > 0) yp.segment(u, u) = consistent_accelerations(p, t, y);
  p.expand(t, y, yp.data());
  generalised_forces(p.model, p.q, p.v, p.a, p.terms, p.F);
  OutputSample s;
  s.t = t;
  s.q = p.q;
  s.v = p.v;
  s.a = p.a;
  s.tau = p.torques(t);
  s.energy = energies(p.model, p.q, p.v);
  s.dissipated = y[2 * u];
  s.input_work = y[2 * u + 1];
  return s;
}

}  // namespace

RunOutcome integrate(const Model& model, const std::vector<JointInput>& inputs, const IntegratorOptions& opts,
                     const std::function<void(const OutputSample&)>& sink, const std::atomic<int>* stop) {
  if (static_cast<int>(inputs.size()) != model.m())
    throw std::invalid_argument("one input per joint is required");
  int nb = 0;
  for (const auto& in : inputs) nb += in.prescribed() ? 0 : 1;
  Problem p(model, inputs, stop);
  p.terms = opts.forces;
  const int n6 = 6 * model.n();
  for (int i = 0; i < n6; ++i) p.unknown.push_back(i);
  p.base_col.assign(model.m(), -1);
  for (int j = 0; j < model.m(); ++j)
    if (!inputs[j].prescribed()) {
      p.base_col[j] = static_cast<int>(p.unknown.size());
      p.unknown.push_back(n6 + j);
    }
  p.newton = std::make_unique<NewtonSystem>(model, p.base_col, nb);
  const int u = p.nu(), N = 2 * u + 2;
  const long n_out = std::lround(std::ceil(opts.t_end / opts.output_dt - 1e-9));
  RunOutcome out;

  // Initial state: rfes undeformed and at rest, free joints at their initial values and rates.
  VecX y0 = VecX::Zero(N), yp0 = VecX::Zero(N);
  for (int j = 0; j < model.m(); ++j)
    if (!inputs[j].prescribed()) {
      y0[p.base_col[j]] = inputs[j].q0;
      y0[u + p.base_col[j]] = inputs[j].v0;
    }
  if (u > 0) {
    const VecX a0 = consistent_accelerations(p, 0.0, y0.data());
    yp0.head(u) = y0.segment(u, u);
    yp0.segment(u, u) = a0;
    p.expand(0.0, y0.data(), yp0.data());
    generalised_forces(model, p.q, p.v, p.a, p.terms, p.F);
    yp0[2 * u] = p.damped ? energies(model, p.q, p.v).dissipation_rate : 0.0;
    yp0[2 * u + 1] = p.input_power(p.torques(0.0));
  }
  if (u == 0) {  // rigid manipulator with every joint prescribed: inverse dynamics at each output
    double W = 0.0, last_t = 0.0, last_P = 0.0;
    for (long k = 0; k <= n_out; ++k) {
      const double t = std::min(opts.t_end, k * opts.output_dt);
      if (stop && stop->load()) {
        out.status = "interrupted (signal " + std::to_string(stop->load()) + ")";
        return out;
      }
      OutputSample s = sample(p, t, y0.data());
      const double P = p.input_power(s.tau);
      W += 0.5 * (P + last_P) * (t - last_t);  // ∫ τ·q̇ dt, trapezoidal between outputs
      s.input_work = W;
      last_t = t;
      last_P = P;
      sink(s);
      out.t_reached = t;
    }
    out.completed = true;
    out.status = "completed";
    return out;
  }
  sink(sample(p, 0.0, y0.data()));

  IdaHandles h;
  check(SUNContext_Create(nullptr, &h.ctx), "SUNContext_Create");
  h.y = N_VNew_Serial(N, h.ctx);
  h.yp = N_VNew_Serial(N, h.ctx);
  std::copy(y0.data(), y0.data() + N, N_VGetArrayPointer(h.y));
  std::copy(yp0.data(), yp0.data() + N, N_VGetArrayPointer(h.yp));
  h.ida = IDACreate(h.ctx);
  check(IDAInit(h.ida, residual, 0.0, h.y, h.yp), "IDAInit");
  N_Vector abstol = N_VNew_Serial(N, h.ctx);
  double* at = N_VGetArrayPointer(abstol);
  for (int i = 0; i < u; ++i) {
    at[i] = opts.atol;
    at[u + i] = opts.atol_velocity;
  }
  at[2 * u] = at[2 * u + 1] = opts.atol_energy;
  const int tol_flag = IDASVtolerances(h.ida, opts.rtol, abstol);
  N_VDestroy(abstol);
  check(tol_flag, "IDASVtolerances");
  check(IDASetUserData(h.ida, &p), "IDASetUserData");
  // IDA's own messages are silenced: failures are reported once, with advice, in RunOutcome.
  check(IDASetErrHandlerFn(h.ida, [](int, const char*, const char*, char*, void*) {}, nullptr), "IDASetErrHandlerFn");
  check(IDASetMaxNumSteps(h.ida, opts.max_steps), "IDASetMaxNumSteps");
  if (opts.max_step > 0) check(IDASetMaxStep(h.ida, opts.max_step), "IDASetMaxStep");
  check(IDASetMaxOrd(h.ida, opts.max_order), "IDASetMaxOrd");
  check(IDASetStopTime(h.ida, opts.t_end), "IDASetStopTime");  // tabulated inputs end at t_end
  h.A = SUNMatNewEmpty(h.ctx);
  h.A->ops->getid = mat_id;
  h.A->ops->zero = mat_zero;
  h.A->ops->destroy = mat_destroy;
  h.ls = SUNLinSolNewEmpty(h.ctx);
  h.ls->content = &p;
  h.ls->ops->gettype = ls_type;
  h.ls->ops->setup = ls_setup;
  h.ls->ops->solve = ls_solve;
  h.ls->ops->free = ls_free;
  check(IDASetLinearSolver(h.ida, h.ls, h.A), "IDASetLinearSolver");
  check(IDASetJacFn(h.ida, jacobian), "IDASetJacFn");

  auto stats = [&] {
    IDAGetNumSteps(h.ida, &out.stats.steps);
    IDAGetNumResEvals(h.ida, &out.stats.residual_evals);
    IDAGetNumJacEvals(h.ida, &out.stats.factorizations);
    IDAGetNumNonlinSolvIters(h.ida, &out.stats.newton_iters);
    IDAGetNumNonlinSolvConvFails(h.ida, &out.stats.newton_fails);
    IDAGetNumErrTestFails(h.ida, &out.stats.error_test_fails);
    IDAGetLastStep(h.ida, &out.stats.last_step);
  };
  for (long k = 1; k <= n_out; ++k) {
    const double tout = std::min(opts.t_end, k * opts.output_dt);
    sunrealtype tret = 0.0;
    const int flag = IDASolve(h.ida, tout, &tret, h.y, h.yp, IDA_NORMAL);
    stats();
    if (stop && stop->load()) {
      out.status = "interrupted (signal " + std::to_string(stop->load()) + ")";
      return out;
    }
    if (flag < 0) {
      double tcur = 0.0;
      IDAGetCurrentTime(h.ida, &tcur);
      char buf[160];
      std::snprintf(buf, sizeof buf, " at t = %.6g s (last step %.3g s)", tcur, out.stats.last_step);
      out.status = "failed: IDA " + flag_name(flag) + buf +
                   "; try looser tolerances, a smaller max_step, or check the inputs";
      return out;
    }
    OutputSample smp = sample(p, tret, N_VGetArrayPointer(h.y));
    smp.steps = out.stats.steps;
    smp.last_step = out.stats.last_step;
    sink(smp);
    out.t_reached = tret;
  }
  out.completed = true;
  out.status = "completed";
  return out;
}

}  // namespace rfem
