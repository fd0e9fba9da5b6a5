// SUNDIALS IDA (variable-step BDF) on y = [q_u; v_u; dissipated; input work] with our own linear
// solver: IDA hands c_j to the Jacobian function, which assembles and factorises
// S = c_j² M + c_j C + K; the 2N Newton system is solved through that Schur complement
// (solvers/newton_system.hpp). Exceptions never cross IDA's C frames: every callback catches, keeps
// the message and returns a failure flag; the run's status then carries that message.
#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sundials/sundials_matrix.h>

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <cstdlib>
#include <stdexcept>

#include "rfem/solvers/integrator.hpp"
#include "rfem/solvers/sundials_impl.hpp"

namespace rfem {

namespace {

struct Bdf {
  EquationsOfMotion& eq;
  SampleEmitter& emit;
  double cj_factor = 0.0;
  VecX r;               // residual scratch (unknowns)
  void* ida = nullptr;  // for the heartbeat's step count
  std::string error;    // what a callback caught (IDA itself only sees a flag)
  std::string ida_message;  // IDA's own text of its last error (it outlives IDA: declared first)
  int caught(const std::exception& e) {
    if (error.empty()) error = e.what();
    return -1;  // unrecoverable
  }
};

int residual(sunrealtype t, N_Vector yv, N_Vector ypv, N_Vector rv, void* data) {
  auto& p = *static_cast<Bdf*>(data);
  if (p.eq.stop_requested()) return -1;  // unrecoverable: the caller reports the interruption
  long steps = 0;
  if (p.ida) IDAGetNumSteps(p.ida, &steps);
  if (!p.emit.beat(t, steps)) return -1;  // (the caller reports the heartbeat's failure)
  const double *y = N_VGetArrayPointer(yv), *yp = N_VGetArrayPointer(ypv);
  double* r = N_VGetArrayPointer(rv);
  const int u = p.eq.unknowns();
  Power P;
  try {
    P = p.eq.residual(t, y, y + u, yp + u, r + u);
  } catch (const std::exception& e) {
    return p.caught(e);
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
  } catch (const std::exception& e) {
    return p.caught(e);
  }
}

int ls_solve(SUNLinearSolver ls, SUNMatrix, N_Vector xv, N_Vector bv, sunrealtype) {
  auto& p = *static_cast<Bdf*>(ls->content);
  const double* b = N_VGetArrayPointer(bv);
  double* x = N_VGetArrayPointer(xv);
  const int u = p.eq.unknowns();
  try {
    p.eq.solve_newton_bdf(b, x);
  } catch (const std::exception& e) {
    return p.caught(e);
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
  sundials::Context ctx;
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

RunOutcome integrate_bdf(EquationsOfMotion& eq, const IntegratorOptions& opts, SampleEmitter& emit) {
  Bdf p{eq, emit, 0.0, VecX(), nullptr, {}, {}};
  const int u = eq.unknowns(), N = 2 * u + 2;
  const long n_out = output_count(opts);
  RunOutcome out;

  VecX y0 = VecX::Zero(N), yp0 = VecX::Zero(N), qu, vu;
  // A resumed run restarts IDA at its checkpoint (order 1, a fresh history): the same solution
  // within the tolerances, not bit for bit.
  const IntegratorState* resume = emit.resume();
  const double t0 = resume ? resume->t : 0.0;
  IntegratorStats before;  // counters of the run before the checkpoint
  p.r.resize(u);
  if (resume) {
    if (resume->q.size() != u || resume->v.size() != u || resume->a.size() != u)
      throw std::invalid_argument("the state to resume from has " + std::to_string(resume->q.size()) +
                                  " unknowns, the model " + std::to_string(u));
    if (resume->next_output < 1 || resume->next_output > n_out + 1)
      throw std::invalid_argument("the state to resume from does not fit the run's outputs (another t_end or output_dt?)");
    y0 << resume->q, resume->v, resume->dissipated, resume->input_work;
    yp0 << resume->v, resume->a, resume->power.dissipation, resume->power.input;
    before = resume->stats;
    out.t_reached = output_time(opts, resume->next_output - 1);
  } else {
    try {  // the start can fail like any step: a status, not an exception
      eq.initial_state(qu, vu, opts.initial == InitialState::Static);
      y0.head(u) = qu;
      y0.segment(u, u) = vu;
      const VecX a0 = eq.accelerations(0.0, qu.data(), vu.data());
      yp0.head(u) = vu;
      yp0.segment(u, u) = a0;
      const Power P0 = eq.residual(0.0, qu.data(), vu.data(), a0.data(), p.r.data());
      yp0[2 * u] = P0.dissipation;
      yp0[2 * u + 1] = P0.input;
      if (!y0.allFinite() || !yp0.allFinite()) throw std::runtime_error("the initial state is not finite (check the inputs' values)");
      if (!emit(eq.sample(0.0, qu.data(), vu.data(), a0.data(), 0.0, 0.0))) {
        out.status = emit.failure();
        return out;
      }
    } catch (const std::exception& e) {
      out.status = RunStatus::failed(at_start(e.what()));
      return out;
    }
  }

  IdaHandles h;
  h.y = N_VNew_Serial(N, h.ctx.get());
  h.yp = N_VNew_Serial(N, h.ctx.get());
  if (!h.y || !h.yp) throw std::runtime_error("N_VNew_Serial failed");
  std::copy(y0.data(), y0.data() + N, N_VGetArrayPointer(h.y));
  std::copy(yp0.data(), yp0.data() + N, N_VGetArrayPointer(h.yp));
  h.ida = IDACreate(h.ctx.get());
  if (!h.ida) throw std::runtime_error("IDACreate failed");
  p.ida = h.ida;
  check(IDAInit(h.ida, residual, t0, h.y, h.yp), "IDAInit");
  if (resume) check(IDASetInitStep(h.ida, resume->h), "IDASetInitStep");
  N_Vector abstol = N_VNew_Serial(N, h.ctx.get());
  if (!abstol) throw std::runtime_error("N_VNew_Serial failed");
  double* at = N_VGetArrayPointer(abstol);
  for (int i = 0; i < u; ++i) {
    at[i] = opts.atol;
    at[u + i] = opts.atol_velocity;
  }
  at[2 * u] = at[2 * u + 1] = opts.atol_energy;
  // Modal derivatives are quasi-static corrections (Reduction::quasi_static): out of IDA's error
  // test by a weight of ~0 (IDA has no mask for differential unknowns; its Newton test then
  // leaves them out too).
  for (int i : eq.quasi_static()) at[i] = at[u + i] = 1e300;
  const int tol_flag = IDASVtolerances(h.ida, opts.rtol, abstol);
  N_VDestroy(abstol);
  check(tol_flag, "IDASVtolerances");
  check(IDASetUserData(h.ida, &p), "IDASetUserData");
  check(sundials::capture_ida_messages(h.ida, h.ctx, &p.ida_message), "setting IDA's error handler");
  check(IDASetMaxNumSteps(h.ida, opts.max_steps), "IDASetMaxNumSteps");
  if (opts.max_step > 0) check(IDASetMaxStep(h.ida, opts.max_step), "IDASetMaxStep");
  check(IDASetMaxOrd(h.ida, opts.max_order), "IDASetMaxOrd");
  check(IDASetStopTime(h.ida, opts.t_end), "IDASetStopTime");  // tabulated inputs end at t_end
  h.A = SUNMatNewEmpty(h.ctx.get());
  h.ls = SUNLinSolNewEmpty(h.ctx.get());
  if (!h.A || !h.ls) throw std::runtime_error("SUNMatNewEmpty / SUNLinSolNewEmpty failed");
  h.A->ops->getid = mat_id;
  h.A->ops->zero = mat_zero;
  h.A->ops->destroy = mat_destroy;
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
    for (auto [sum, was] : {std::pair{&out.stats.steps, before.steps}, {&out.stats.residual_evals, before.residual_evals},
                            {&out.stats.factorizations, before.factorizations}, {&out.stats.newton_iters, before.newton_iters},
                            {&out.stats.newton_fails, before.newton_fails}, {&out.stats.error_test_fails, before.error_test_fails}})
      *sum += was;
  };
  for (long k = resume ? resume->next_output : 1; k <= n_out; ++k) {
    const double tout = output_time(opts, k);
    sunrealtype tret = 0.0;
    const int flag = IDASolve(h.ida, tout, &tret, h.y, h.yp, IDA_NORMAL);
    stats();
    if (eq.stop_requested()) {
      out.status = RunStatus::interrupted(eq.stop().signal());
      return out;
    }
    if (emit.failed()) {  // the heartbeat failed inside IDA
      out.status = emit.failure();
      return out;
    }
    double tcur = 0.0;
    IDAGetCurrentTime(h.ida, &tcur);
    char buf[160];
    std::snprintf(buf, sizeof buf, " at t = %.6g s (last step %.3g s)", tcur, out.stats.last_step);
    if (flag < 0) {
      // What a callback caught, else IDA's flag with its own message.
      const std::string why = !p.error.empty() ? p.error
                              : "IDA " + flag_name(flag) + (p.ida_message.empty() ? "" : " (" + p.ida_message + ")");
      out.status = RunStatus::failed(why + buf +
                                     "; try looser tolerances, a smaller max_step, or check the inputs");
      return out;
    }
    const double* y = N_VGetArrayPointer(h.y);
    if (!std::all_of(y, y + N, [](double x) { return std::isfinite(x); })) {
      out.status = RunStatus::failed(std::string("the solution is not finite") + buf + "; check the inputs");
      return out;
    }
    // Accelerations from the equations at the output state (IDA's interpolated y' is only first
    // order under BDF2).
    OutputSample smp;
    try {
      smp = eq.sample(tret, y, y + u, nullptr, y[2 * u], y[2 * u + 1]);
    } catch (const std::exception& e) {
      out.status = RunStatus::failed(e.what() + std::string(buf));
      return out;
    }
    smp.steps = out.stats.steps;
    smp.last_step = out.stats.last_step;
    const bool emitted = emit(smp);
    eq.give_back(smp);
    if (!emitted) {
      out.status = emit.failure();
      return out;
    }
    out.t_reached = tret;
    // A checkpoint at the output: IDA's state there with the accelerations and powers of the
    // equations (its interpolated y' is first order), and the next step it would take.
    const bool saved = emit.checkpoint([&] {
      IntegratorState x;
      x.t = tret;
      x.q = Eigen::Map<const VecX>(y, u);
      x.v = Eigen::Map<const VecX>(y + u, u);
      x.a = eq.accelerations(tret, y, y + u);
      x.power = eq.residual(tret, y, y + u, x.a.data(), p.r.data());
      x.dissipated = y[2 * u];
      x.input_work = y[2 * u + 1];
      double h_next = 0.0;
      IDAGetCurrentStep(h.ida, &h_next);
      x.h = h_next > 0 ? h_next : out.stats.last_step;
      x.next_output = k + 1;
      x.stats = out.stats;
      return x;
    });
    if (!saved) {
      out.status = emit.failure();
      return out;
    }
  }
  out.status = RunStatus::completed();
  return out;
}

}  // namespace rfem
