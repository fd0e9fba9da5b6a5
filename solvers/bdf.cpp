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

#include "../core/check.hpp"
#include "stepper.hpp"
#include "sundials_impl.hpp"

namespace rfem {

namespace {

struct Bdf {
  EquationsOfMotion& eq;
  SampleEmitter* emit = nullptr;  // the current call's
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
  if (!p.emit->beat(t, steps)) return -1;  // (the caller reports the heartbeat's failure)
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


// IDA behind the stepper interface: one IDA memory from start() to the end of the run, its outputs
// the run's grid; a caller's stop between outputs is IDA's stop time there.
class BdfStepper final : public Stepper {
 public:
  BdfStepper(EquationsOfMotion& eq, const IntegratorOptions& opts)
      : eq_(eq), o_(opts), p_{eq, nullptr, 0.0, VecX(), nullptr, {}, {}}, u_(eq.unknowns()), N_(2 * u_ + 2), n_out_(output_count(opts)) {}

  RunStatus start(SampleEmitter& emit) override;
  RunStatus advance(double until, SampleEmitter& emit) override;
  void inputs_changed() override;
  double time() const override { return t_; }
  double t_reached() const override { return t_reached_; }
  const IntegratorStats& stats() const override { return st_; }
  IntegratorState state() const override;

 private:
  void collect_stats();
  // IDASolve to `tout` (an output, or the caller's stop): Running, or how it failed.
  RunStatus solve_to(double tout, double& tret);
  EquationsOfMotion& eq_;
  const IntegratorOptions o_;
  Bdf p_;         // (before h_: IDA's user data outlives IDA)
  IdaHandles h_;
  const int u_, N_;
  const long n_out_;
  long k_ = 1;    // the next output
  double t_ = 0.0, t_reached_ = 0.0;
  IntegratorStats before_, st_;  // the counters of the run before IDA's memory was (re)started; all
  bool started_ = false;
};

RunStatus BdfStepper::start(SampleEmitter& emit) {
  RFEM_CHECK_ARGUMENT(!started_, "the stepper has started already");
  started_ = true;
  Bdf& p = p_;
  p.emit = &emit;
  const int u = u_, N = N_;
  VecX y0 = VecX::Zero(N), yp0 = VecX::Zero(N), qu, vu;
  // A resumed run restarts IDA at its checkpoint (order 1, a fresh history): the same solution
  // within the tolerances, not bit for bit.
  const IntegratorState* resume = emit.resume();
  const double t0 = resume ? resume->t : 0.0;
  p.r.resize(u);
  if (resume) {
    if (resume->q.size() != u || resume->v.size() != u || resume->a.size() != u)
      throw std::invalid_argument("the state to resume from has " + std::to_string(resume->q.size()) +
                                  " unknowns, the model " + std::to_string(u));
    if (resume->next_output < 1 || resume->next_output > n_out_ + 1)
      throw std::invalid_argument("the state to resume from does not fit the run's outputs (another t_end or output_dt?)");
    y0 << resume->q, resume->v, resume->dissipated, resume->input_work;
    yp0 << resume->v, resume->a, resume->power.dissipation, resume->power.input;
    before_ = st_ = resume->stats;
    t_reached_ = output_time(o_, resume->next_output - 1);
    k_ = resume->next_output;
  } else {
    try {  // the start can fail like any step: a status, not an exception
      eq_.initial_state(qu, vu, o_.initial == InitialState::Static);
      y0.head(u) = qu;
      y0.segment(u, u) = vu;
      const VecX a0 = eq_.accelerations(0.0, qu.data(), vu.data());
      yp0.head(u) = vu;
      yp0.segment(u, u) = a0;
      const Power P0 = eq_.residual(0.0, qu.data(), vu.data(), a0.data(), p.r.data());
      yp0[2 * u] = P0.dissipation;
      yp0[2 * u + 1] = P0.input;
      if (!y0.allFinite() || !yp0.allFinite()) throw std::runtime_error("the initial state is not finite (check the inputs' values)");
      if (!emit(eq_.sample(0.0, qu.data(), vu.data(), a0.data(), 0.0, 0.0))) return emit.failure();
    } catch (const std::exception& e) {
      return RunStatus::failed(at_start(e.what()));
    }
  }
  t_ = t0;

  IdaHandles& h = h_;
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
    at[i] = o_.atol;
    at[u + i] = o_.atol_velocity;
  }
  at[2 * u] = at[2 * u + 1] = o_.atol_energy;
  // Modal derivatives are quasi-static corrections (Reduction::quasi_static): out of IDA's error
  // test by a weight of ~0 (IDA has no mask for differential unknowns; its Newton test then
  // leaves them out too).
  for (int i : eq_.quasi_static()) at[i] = at[u + i] = 1e300;
  const int tol_flag = IDASVtolerances(h.ida, o_.rtol, abstol);
  N_VDestroy(abstol);
  check(tol_flag, "IDASVtolerances");
  check(IDASetUserData(h.ida, &p), "IDASetUserData");
  check(sundials::capture_ida_messages(h.ida, h.ctx, &p.ida_message), "setting IDA's error handler");
  check(IDASetMaxNumSteps(h.ida, o_.max_steps), "IDASetMaxNumSteps");
  if (o_.max_step > 0) check(IDASetMaxStep(h.ida, o_.max_step), "IDASetMaxStep");
  check(IDASetMaxOrd(h.ida, o_.max_order), "IDASetMaxOrd");
  check(IDASetStopTime(h.ida, o_.t_end), "IDASetStopTime");  // tabulated inputs end at t_end
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
  return RunStatus{};
}

void BdfStepper::collect_stats() {
  void* ida = h_.ida;
  IntegratorStats& s = st_;
  IDAGetNumSteps(ida, &s.steps);
  IDAGetNumResEvals(ida, &s.residual_evals);
  IDAGetNumJacEvals(ida, &s.factorizations);
  IDAGetNumNonlinSolvIters(ida, &s.newton_iters);
  IDAGetNumNonlinSolvConvFails(ida, &s.newton_fails);
  IDAGetNumErrTestFails(ida, &s.error_test_fails);
  IDAGetLastStep(ida, &s.last_step);
  const IntegratorStats& b = before_;
  for (auto [sum, was] : {std::pair{&s.steps, b.steps}, {&s.residual_evals, b.residual_evals},
                          {&s.factorizations, b.factorizations}, {&s.newton_iters, b.newton_iters},
                          {&s.newton_fails, b.newton_fails}, {&s.error_test_fails, b.error_test_fails}})
    *sum += was;
}

RunStatus BdfStepper::solve_to(double tout, double& tret) {
  const int flag = IDASolve(h_.ida, tout, &tret, h_.y, h_.yp, IDA_NORMAL);
  collect_stats();
  if (eq_.stop_requested()) return RunStatus::interrupted(eq_.stop().signal());
  if (p_.emit->failed()) return p_.emit->failure();  // the heartbeat failed inside IDA
  double tcur = 0.0;
  IDAGetCurrentTime(h_.ida, &tcur);
  char buf[160];
  std::snprintf(buf, sizeof buf, " at t = %.6g s (last step %.3g s)", tcur, st_.last_step);
  if (flag < 0) {
    // What a callback caught, else IDA's flag with its own message.
    const std::string why = !p_.error.empty() ? p_.error
                            : "IDA " + flag_name(flag) + (p_.ida_message.empty() ? "" : " (" + p_.ida_message + ")");
    return RunStatus::failed(why + buf + "; try looser tolerances, a smaller max_step, or check the inputs");
  }
  const double* y = N_VGetArrayPointer(h_.y);
  if (!std::all_of(y, y + N_, [](double x) { return std::isfinite(x); }))
    return RunStatus::failed(std::string("the solution is not finite") + buf + "; check the inputs");
  return RunStatus{};
}

RunStatus BdfStepper::advance(double until, SampleEmitter& emit) {
  RFEM_CHECK_ARGUMENT(started_, "start() first");
  RFEM_CHECK_ARGUMENT(until >= t_ && until <= o_.t_end, "until must lie in [t, t_end]");
  p_.emit = &emit;
  const int u = u_;
  while (k_ <= n_out_ && output_time(o_, k_) <= until) {
    double tret = 0.0;
    if (RunStatus s = solve_to(output_time(o_, k_), tret); s.kind != RunStatus::Kind::Running) return s;
    const double* y = N_VGetArrayPointer(h_.y);
    // Accelerations from the equations at the output state (IDA's interpolated y' is only first
    // order under BDF2).
    OutputSample smp;
    try {
      smp = eq_.sample(tret, y, y + u, nullptr, y[2 * u], y[2 * u + 1]);
    } catch (const std::exception& e) {
      char buf[160];
      std::snprintf(buf, sizeof buf, " at t = %.6g s (last step %.3g s)", tret, st_.last_step);
      return RunStatus::failed(e.what() + std::string(buf));
    }
    smp.steps = st_.steps;
    smp.last_step = st_.last_step;
    const bool emitted = emit(smp);
    eq_.give_back(smp);
    if (!emitted) return emit.failure();
    t_ = t_reached_ = tret;
    // A checkpoint at the output: IDA's state there with the accelerations and powers of the
    // equations (its interpolated y' is first order), and the next step it would take.
    ++k_;  // (the next output: the state's)
    if (!emit.checkpoint([&] { return state(); })) return emit.failure();
  }
  if (t_ < until) {  // the caller's stop between two outputs: IDA's stop time there
    check(IDASetStopTime(h_.ida, until), "IDASetStopTime");
    double tret = 0.0;
    if (RunStatus s = solve_to(until, tret); s.kind != RunStatus::Kind::Running) return s;
    t_ = until;
    check(IDASetStopTime(h_.ida, o_.t_end), "IDASetStopTime");
  }
  return t_ >= o_.t_end ? RunStatus::completed() : RunStatus{};
}

void BdfStepper::inputs_changed() {
  RFEM_CHECK_ARGUMENT(started_, "start() first");
  // IDA starts afresh from the right limit at t (its history assumed the old inputs).
  const int u = u_;
  double* y = N_VGetArrayPointer(h_.y);
  double* yp = N_VGetArrayPointer(h_.yp);
  const VecX a = eq_.accelerations(t_, y, y + u);
  const Power P = eq_.residual(t_, y, y + u, a.data(), p_.r.data());
  std::copy(y + u, y + 2 * u, yp);
  std::copy(a.data(), a.data() + u, yp + u);
  yp[2 * u] = P.dissipation;
  yp[2 * u + 1] = P.input;
  before_ = st_;  // (IDAReInit sets IDA's counters to zero)
  check(IDAReInit(h_.ida, t_, h_.y, h_.yp), "IDAReInit");
  check(IDASetStopTime(h_.ida, o_.t_end), "IDASetStopTime");
}

IntegratorState BdfStepper::state() const {
  const int u = u_;
  const double* y = N_VGetArrayPointer(h_.y);
  IntegratorState x;
  x.t = t_;
  x.q = Eigen::Map<const VecX>(y, u);
  x.v = Eigen::Map<const VecX>(y + u, u);
  x.a = eq_.accelerations(t_, y, y + u);
  VecX r(u);
  x.power = eq_.residual(t_, y, y + u, x.a.data(), r.data());
  x.dissipated = y[2 * u];
  x.input_work = y[2 * u + 1];
  double h_next = 0.0;
  if (h_.ida) IDAGetCurrentStep(h_.ida, &h_next);
  // (before IDA's first step: a guess it may change; IDA's own first guess is of that size)
  x.h = h_next > 0 ? h_next : st_.last_step > 0 ? st_.last_step : 1e-3 * o_.output_dt;
  x.next_output = k_;
  x.stats = st_;
  return x;
}

}  // namespace

std::unique_ptr<Stepper> make_bdf_stepper(EquationsOfMotion& eq, const IntegratorOptions& opts) {
  return std::make_unique<BdfStepper>(eq, opts);
}

}  // namespace rfem
