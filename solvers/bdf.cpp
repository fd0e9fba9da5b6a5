// SUNDIALS IDA (variable-step BDF) on y = [q_u; v_u; dissipated; input work] with our own linear
// solver: IDA hands c_j to the Jacobian function, which assembles and factorises
// S = c_j² M + c_j C + K; the 2N Newton system is solved through that Schur complement
// (solvers/newton_system.hpp). Exceptions never cross IDA's C frames: every callback catches.
#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

#include "solvers/integrator.hpp"

namespace rfem {

namespace {

struct Bdf {
  EquationsOfMotion& eq;
  double cj_factor = 0.0;
  VecX r;  // residual scratch (unknowns)
};

int residual(sunrealtype t, N_Vector yv, N_Vector ypv, N_Vector rv, void* data) {
  auto& p = *static_cast<Bdf*>(data);
  if (p.eq.stop_requested()) return -1;  // unrecoverable: the caller reports the interruption
  const double *y = N_VGetArrayPointer(yv), *yp = N_VGetArrayPointer(ypv);
  double* r = N_VGetArrayPointer(rv);
  const int u = p.eq.unknowns();
  Power P;
  try {
    P = p.eq.residual(t, y, y + u, yp + u, r + u);
  } catch (const std::exception&) {
    return -1;
  }
  for (int i = 0; i < u; ++i) r[i] = yp[i] - y[u + i];
  r[2 * u] = yp[2 * u] - P.dissipation;
  r[2 * u + 1] = yp[2 * u + 1] - P.input;
  for (int i = 0; i < 2 * u + 2; ++i)
    if (!std::isfinite(r[i])) return 1;  // recoverable: IDA retries with a smaller step
  return 0;
}

// IDA hands us c_j here: assemble S and K at the current y and factorise.
int jacobian(sunrealtype t, sunrealtype cj, N_Vector yv, N_Vector, N_Vector, SUNMatrix, void* data, N_Vector,
             N_Vector, N_Vector) {
  auto& p = *static_cast<Bdf*>(data);
  try {
    const double* y = N_VGetArrayPointer(yv);
    p.cj_factor = cj;
    return p.eq.setup_newton(t, y, y + p.eq.unknowns(), 1.0 / cj) ? 0 : 1;
  } catch (const std::exception&) {
    return -1;
  }
}

int ls_solve(SUNLinearSolver ls, SUNMatrix, N_Vector xv, N_Vector bv, sunrealtype) {
  auto& p = *static_cast<Bdf*>(ls->content);
  const double* b = N_VGetArrayPointer(bv);
  double* x = N_VGetArrayPointer(xv);
  const int u = p.eq.unknowns();
  try {
    p.eq.newton().solve_bdf(b, x);
  } catch (const std::exception&) {
    return -1;
  }
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

}  // namespace

RunOutcome integrate_bdf(EquationsOfMotion& eq, const IntegratorOptions& opts, const SampleSink& sink) {
  Bdf p{eq, 0.0, VecX()};
  const int u = eq.unknowns(), N = 2 * u + 2;
  const long n_out = std::lround(std::ceil(opts.t_end / opts.output_dt - 1e-9));
  RunOutcome out;

  VecX y0 = VecX::Zero(N), yp0 = VecX::Zero(N), qu, vu;
  eq.initial_state(qu, vu, opts.initial == InitialState::Static);
  y0.head(u) = qu;
  y0.segment(u, u) = vu;
  const VecX a0 = eq.accelerations(0.0, qu.data(), vu.data());
  yp0.head(u) = vu;
  yp0.segment(u, u) = a0;
  p.r.resize(u);
  const Power P0 = eq.residual(0.0, qu.data(), vu.data(), a0.data(), p.r.data());
  yp0[2 * u] = P0.dissipation;
  yp0[2 * u + 1] = P0.input;
  sink(eq.sample(0.0, qu.data(), vu.data(), a0.data(), 0.0, 0.0));

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
    if (eq.stop_requested()) {
      out.status = "interrupted (signal " + std::to_string(eq.stop_signal()) + ")";
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
    const double* y = N_VGetArrayPointer(h.y);
    // Accelerations from the equations at the output state (IDA's interpolated y' is only first
    // order under BDF2).
    OutputSample smp = eq.sample(tret, y, y + u, nullptr, y[2 * u], y[2 * u + 1]);
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
