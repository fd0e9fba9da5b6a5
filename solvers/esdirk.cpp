// ESDIRK time integration of the second-order equations r(t, q, v, a) = 0 (solvers/equations.hpp).
//
// An s-stage ESDIRK method (A lower triangular, a_00 = 0, a_ii = γ for i ≥ 1, stiffly accurate:
// b = last row of A) applied to q' = v, v' = a, written in the stage accelerations α_i:
//   V_i = v_n + h Σ_j a_ij α_j,   Q_i = q_n + c_i h v_n + h² Σ_j (A²)_ij α_j,
//   r(t_n + c_i h, Q_i, V_i, α_i) = 0        (i = 1 … s−1; α_0 = a_n, the previous last stage).
// The q-equation is satisfied exactly, so each stage is a Newton iteration on α_i alone with the
// matrix ∂r/∂a + hγ ∂r/∂v + (hγ)² ∂r/∂q ≈ S = M + hγ C + (hγ)² K: the bordered symmetric positive
// definite matrix of the Newton system (solvers/newton_system.hpp), assembled and factorised once per
// step and shared by its stages.
// L-stability and stiff accuracy damp the undamped stiff sde modes (ω up to ~1e5 rad/s) that the
// steps do not resolve; the tables whose embedded method is L-stable too (ESDIRK436L2SA,
// ESDIRK43I6L2SA, ESDIRK437L2SA) keep those modes out of the error estimate as well.
// Error estimate: the embedded solution (weights d): e_v = h Σ (b−d)_j α_j,
// e_q = h² Σ ((b−d)ᵀA)_j α_j, in the weighted RMS norm of rtol and atol (IDA's convention).
// Outputs between steps: quintic Hermite interpolation of q from (q, v, a) at both ends, its first
// and second derivatives for v and a (the accelerations of the continuous solution).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "../core/check.hpp"
#include "esdirk_stepper.hpp"
#include "esdirk_tableau.hpp"
#include "team_parts.hpp"

namespace rfem {

namespace {

using namespace esdirk;

// Newton iteration and step-size control parameters.
constexpr int kMaxNewton = 7;
// Newton tolerance on the stage increment, in units of the error tolerance and in the max norm: a
// weighted RMS over thousands of coordinates would hide an error confined to a few (a free joint,
// the first rfes' torsion) that the next steps amplify. 0.02 costs ~6 % more iterations than 0.05
// and halves the force-input error of the paper's case (bench/work_precision.py).
constexpr double kNewtonTol = 0.02;
constexpr double kSafety = 0.9, kMinFactor = 0.2, kMaxFactor = 5.0;
// The first Newton increment after the predictor may grow this much before the step is cut (4 and
// 100 took the same steps on the paper's force run; 0.99, the later rates' bound, 14–70 % more).
constexpr double kFirstGrowth = 4.0;

}  // namespace

void check_esdirk_table(const std::string& name) { load_tableau(name); }

// The integrator's state between steps, and its step loop (the equations and options are the
// caller's; the tableau, stage vectors and step control are this object's).
struct EsdirkStepper::Impl {
  EquationsOfMotion& eq;
  const IntegratorOptions o;
  const Tableau T;
  const int u, s;
  IntegratorStats st;
  std::vector<VecX> alpha;  // the stage accelerations α_0 … α_{s−1}
  VecX& a;                  // a_n, which is α_0 (first same as last): one vector, not two
  VecX q, v, r;
  Power P;
  double Wd = 0.0, Wi = 0.0;  // dissipated energy, input work
  std::vector<Power> Ps;
  std::vector<double> cq, cv;  // the coefficients of a combination of the stages
  // s + 9 vectors of the unknowns' size (α, q, v, r, w's two halves, Qk, Vk, Q, V; memory per rfe
  // matters at 10⁴ rfes): after the stages Q, V hold the new solution and Qk, Vk the error estimate,
  // and Qk, Vk, r the outputs between steps.
  VecX w, Qk, Vk, Q, V;
  double h = 0.0, t = 0.0, err_prev = 1.0, eta = 1.0, t_reached = 0.0;
  int max_newton = kMaxNewton;
  bool last_rejected = false;
  bool nonfinite = false;  // a residual or an error estimate was NaN or inf since the last accepted step
  std::vector<double> breaks;
  size_t next_break = 0;
  long n_out = 0, k_out = 1, steps_this_output = 0, attempts_this_output = 0;
  bool started = false;
  // The sample-and-holds the steps stop at (solvers/stepper.hpp: Sampler): the digital laws
  // (TorqueLaw::sample_time > 0), then a caller's (a controller in the loop).
  std::vector<Sampler> samplers;
  // Wall time spent in samplers that see the state (a caller's controller): not the step's, so
  // the thread governor does not count it (solvers/thread_governor.hpp).
  std::chrono::steady_clock::duration in_samplers{};

  Impl(EquationsOfMotion& e, const IntegratorOptions& opts)
      : eq(e), o(opts), T(load_tableau(opts.esdirk_table)), u(e.unknowns()), s(T.s), alpha(s, VecX::Zero(u)),
        a(alpha[0]), r(u), Ps(s), cq(s), cv(s), w(2 * u), Qk(u), Vk(u), Q(u), V(u), breaks(e.breakpoints(opts.t_end)),
        n_out(output_count(opts)) {
    for (int j = 0; j < static_cast<int>(e.inputs().size()); ++j)
      if (const JointInput& in = e.inputs()[j]; !in.prescribed() && in.torque->sample_time() > 0) {
        const int col = e.base_col()[j];
        samplers.push_back({in.torque->sample_time(), 0, false, [this, j, col](double ts) {
                              eq.inputs()[j].torque->sample(ts, q[col], v[col]);
                              return true;
                            }});
      }
  }

  // The next sample of any sampler after t (t_end if none).
  double next_sample_time() const {
    double t_next = o.t_end;
    for (const Sampler& x : samplers) t_next = std::min(t_next, x.next * x.period);
    return t_next;
  }
  void inputs_changed_here() {
    a = eq.accelerations(t, q.data(), v.data());
    P = eq.residual(t, q.data(), v.data(), a.data(), r.data());
    ++st.residual_evals;
  }
  // The samplers whose sample falls on t sample there (in order; one that sees the state sees the
  // inputs the earlier ones set); the accelerations and powers are then those of the new held
  // values (the right limit).
  void sample_due() {
    bool changed = false;
    for (Sampler& x : samplers) {
      while (x.next * x.period <= t + 1e-12 * std::max(1.0, t)) {
        if (std::abs(x.next * x.period - t) <= 1e-12 * std::max(1.0, t)) {
          if (changed && x.needs_state) {
            inputs_changed_here();
            changed = false;
          }
          const auto start = std::chrono::steady_clock::now();
          try {
            changed = x.sample(t) || changed;
          } catch (const std::exception& e) {  // (the sampler's own words: no step failed)
            throw SamplerFailure(e.what());
          }
          if (x.needs_state) in_samplers += std::chrono::steady_clock::now() - start;
        }
        ++x.next;
      }
    }
    if (changed) inputs_changed_here();
  }

  void weights(const VecX& qa, const VecX& va, const VecX* qb, const VecX* vb) {
    for_team_parts(u, eq.team(), [&](long b, long e) {
      for (long i = b; i < e; ++i) {
        const double yq = qb ? std::max(std::abs(qa[i]), std::abs((*qb)[i])) : std::abs(qa[i]);
        const double yv = vb ? std::max(std::abs(va[i]), std::abs((*vb)[i])) : std::abs(va[i]);
        w[i] = 1.0 / (o.rtol * yq + o.atol);
        w[u + i] = 1.0 / (o.rtol * yv + o.atol_velocity);
      }
    });
  }
  // Q, V of stage i from its acceleration α_i (Q = Q_k + (hγ)² α_i, V = V_k + hγ α_i).
  void stage_values(int i, double hg) {
    for_team_parts(u, eq.team(), [&](long b, long e) {
      V.segment(b, e - b) = Vk.segment(b, e - b) + hg * alpha[i].segment(b, e - b);
      Q.segment(b, e - b) = Qk.segment(b, e - b) + (hg * hg) * alpha[i].segment(b, e - b);
    });
  }
  // Stage i's Newton iteration on α_i from its value, with the factorised S; true if converged.
  // `diverged`: the increments grew (the caller restarts from the predictor).
  bool newton_stage(int i, double ti, double hg, bool& diverged) {
    double dn_prev = 0.0;
    diverged = false;
    for (int it = 0; it < max_newton; ++it) {
      stage_values(i, hg);
      Ps[i] = eq.stage_residual(ti, Q.data(), V.data(), alpha[i].data(), r.data());
      ++st.residual_evals;
      ++st.newton_iters;
      eq.solve_newton(r);  // −δα (a residual that is not finite gives a δα that is not)
      // α_i −= δα with the increment's norm; a stage that is not finite is cut (the next attempt
      // starts α_i afresh from its predictor).
      const double dn = wmax_increment(r, hg, w, eq.team(), &alpha[i]);
      if (!std::isfinite(dn)) {
        nonfinite = true;
        return false;
      }
      // Contraction rate θ; give up if it cannot make it within the iterations left. The first
      // rate (predictor → first correction) is no guide: that correction removes the predictor's
      // error in the stiff coordinates, after which the increments shrink fast (measured where the
      // first rate had cut the step: the next increment 0.005–0.2 of the last; docs/performance.md,
      // "Newton's first rate"). It ends the iteration only if the increment grew kFirstGrowth-fold,
      // and declares nothing; the later rates decide.
      bool judged = true;
      if (it == 1 && dn >= 0.99 * dn_prev) {
        if (dn >= kFirstGrowth * dn_prev) {
          diverged = true;
          return false;
        }
        judged = false;
      } else if (it > 0) {
        const double theta = dn / dn_prev;
        if (theta >= 0.99) {
          diverged = true;
          return false;
        }
        eta = theta / (1.0 - theta);
        if (it > 1 && std::pow(theta, max_newton - 1 - it) / (1.0 - theta) * dn > kNewtonTol) return false;
      }
      if ((judged && eta * dn <= kNewtonTol) || dn < 1e-12) {
        // The power was evaluated before this last update: carry it to the converged stage.
        r = -r;  // δα
        const Power dP = eq.power_change(ti, V.data(), r, hg);
        Ps[i].input += dP.input;
        Ps[i].dissipation += dP.dissipation;
        return true;
      }
      dn_prev = dn;
    }
    return false;
  }
  RunStatus fail(const std::string& why) {
    char buf[200];
    std::snprintf(buf, sizeof buf, " at t = %.6g s (step %.3g s)", t, h);
    t_reached = std::max(t_reached, t);
    return RunStatus::failed(why + buf + "; try looser tolerances, a smaller max_step, or check the inputs");
  }
  RunStatus start(SampleEmitter& emit);
  RunStatus advance(double until, SampleEmitter& emit);
  IntegratorState state() const;
  IntegratorState state_scalars() const;  // state() without q, v, a
  // Swaps q, v, a with the state's: lends them to a checkpoint, and takes them back.
  void lend(IntegratorState& x) {
    q.swap(x.q);
    v.swap(x.v);
    a.swap(x.a);
  }
};

RunStatus EsdirkStepper::Impl::start(SampleEmitter& emit) {
  // The start (static equilibrium, initial accelerations) can fail like any step: a status, not an
  // exception. A resumed run starts from its checkpoint instead, its outputs so far delivered.
  started = true;
  const IntegratorState* resume = emit.resume();
  if (resume) {
    if (resume->q.size() != u || resume->v.size() != u || resume->a.size() != u)
      throw std::invalid_argument("the state to resume from has " + std::to_string(resume->q.size()) +
                                  " unknowns, the model " + std::to_string(u));
    q = resume->q;
    v = resume->v;
    a = resume->a;
    P = resume->power;
    Wd = resume->dissipated;
    Wi = resume->input_work;
    st = resume->stats;
    if (resume->next_output < 1 || resume->next_output > output_count(o) + 1 || !(resume->h > 0))
      throw std::invalid_argument("the state to resume from does not fit the run's outputs (another t_end or output_dt?)");
    t_reached = output_time(o, resume->next_output - 1);
  } else {
    try {
      eq.initial_state(q, v, o.initial == InitialState::Static);
      a = eq.accelerations(0.0, q.data(), v.data());
      P = eq.residual(0.0, q.data(), v.data(), a.data(), r.data());
    } catch (const std::exception& e) {
      return RunStatus::failed(at_start(e.what()));
    }
    ++st.residual_evals;
    if (!q.allFinite() || !v.allFinite() || !a.allFinite())
      return RunStatus::failed("the initial state is not finite (check the inputs' values)");
    OutputSample s0;
    try {
      s0 = eq.sample(0.0, q.data(), v.data(), a.data(), 0.0, 0.0);
    } catch (const std::exception& e) {
      return RunStatus::failed(at_start(e.what()));
    }
    if (!emit(s0)) return emit.failure();
  }

  t = resume ? resume->t : 0.0;
  try {
    sample_due();  // (a digital law's first value: at t = 0, or where a resumed run stands)
  } catch (const std::exception& e) {
    return RunStatus::failed(at_start(e.what()));
  }
  // Initial step (Hairer & Wanner I, II.4): 1 % of the time for y to change by its own size.
  weights(q, v, nullptr, nullptr);
  {
    const double d0 = wrms(q, v, w), d1 = wrms(v, a, w);
    h = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    h = std::min({h, o.output_dt, o.t_end});
    if (o.max_step > 0) h = std::min(h, o.max_step);
    h = std::max(h, 1e-10 * o.t_end);
    if (o.fixed_step > 0) h = o.fixed_step;
  }
  if (resume) h = resume->h;
  // Fixed steps cannot be cut: give the Newton iteration room to reach the (tight) tolerance.
  max_newton = o.fixed_step > 0 ? 60 : kMaxNewton;
  t = resume ? resume->t : 0.0;
  err_prev = resume ? resume->err_prev : 1.0;
  eta = resume ? resume->eta : 1.0;
  k_out = resume ? resume->next_output : 1;
  eq.govern_by_steps();
  return RunStatus{};
}

RunStatus EsdirkStepper::Impl::advance(double until, SampleEmitter& emit) {
  auto t_output = [&](long k) { return output_time(o, k); };
  try {
    while (t < until && k_out <= n_out) {
      const auto step_start = std::chrono::steady_clock::now();
      const long residuals_before = st.residual_evals;
      // Every attempt (accepted or not) is timed for the thread governor.
      struct StepTimer {
        EquationsOfMotion& eq;
        std::chrono::steady_clock::time_point start;
        const long& now;
        long before;
        const std::chrono::steady_clock::duration& outside;  // (a controller's time: not the step's)
        std::chrono::steady_clock::duration outside_before;
        ~StepTimer() {
          const auto spent = std::chrono::steady_clock::now() - start - (outside - outside_before);
          eq.report_step(std::chrono::duration<double>(spent).count(), now - before);
        }
      } timer{eq, step_start, st.residual_evals, residuals_before, in_samplers, in_samplers};
      if (eq.stop_requested()) return RunStatus::interrupted(eq.stop().signal());
      if (!emit.beat(t, st.steps)) return emit.failure();
      if (steps_this_output > o.max_steps)
        return fail("more than " + std::to_string(o.max_steps) + " steps in one output interval");
      // Rejected attempts count too: a step that never converges must not retry for ever.
      if (attempts_this_output > 10 * o.max_steps + 100)
        return fail(nonfinite ? "non-finite values (NaN or inf) in the equations"
                              : std::to_string(attempts_this_output) + " step attempts in one output interval");
      ++attempts_this_output;
      if (!(h >= 1e-14 * std::max(1.0, t)))
        return fail(nonfinite || !std::isfinite(h) ? "non-finite values (NaN or inf) in the equations" : "step size underflow");
      // Land exactly on the next breakpoint of the inputs, on the caller's `until` and on t_end;
      // stretch a step that would leave a sliver.
      while (next_break < breaks.size() && breaks[next_break] <= t * (1 + 1e-14)) ++next_break;
      const double t_law = next_break < breaks.size() ? breaks[next_break] : o.t_end;
      const double t_stop = std::min({t_law, until, next_sample_time()});
      // The caller's stops (a controller's samples) come often: two equal steps instead of a step
      // and a sliver, and the step after a stop sized from what the controller proposed before it
      // (a run without such stops takes the same steps as always).
      const bool callers = t_stop < t_law;
      const double h_proposed = h;
      const bool lands = t + 1.05 * h >= t_stop;
      if (lands) h = t_stop - t;
      else if (callers && o.fixed_step <= 0 && t + 2 * h > t_stop) h = 0.5 * (t_stop - t);
      const double hg = h * T.gamma;
      weights(q, v, nullptr, nullptr);

      // The Newton matrix S(hγ) = M + hγ C + (hγ)² K, every step: the base angles turn the border
      // of M and the sde forces turn the geometric part of K fast enough that older matrices cost
      // Newton failures (and accuracy) under force input. It is set up at the step's middle,
      // predicted from (q, v, a), not at its start: the stages lie in [t, t + h], and a reduced
      // link's modal derivatives, coupled to the modes quadratically, turn S's tangent by 10–20 %
      // over a long step (docs/performance.md, "Newton's matrix at the stage"). (Q and V are free
      // until the stages.)
      ++st.factorizations;
      for_team_parts(u, eq.team(), [&](long b, long e) {
        Q.segment(b, e - b) = q.segment(b, e - b) + (0.5 * h) * v.segment(b, e - b) + (0.125 * h * h) * a.segment(b, e - b);
        V.segment(b, e - b) = v.segment(b, e - b) + (0.5 * h) * a.segment(b, e - b);
      });
      bool converged = eq.setup_newton(t + 0.5 * h, Q.data(), V.data(), hg);

      // Stages: α_0 = a_n (first same as last), then one Newton iteration per stage.
      Ps[0] = P;
      for (int i = 1; i < s && converged; ++i) {
        const double ti = t + T.c[i] * h;
        const int team = eq.team();
        for_team_parts(u, team, [&](long b, long e) {  // (Q is free until the Newton iteration)
          Q.segment(b, e - b) = q.segment(b, e - b) + (T.c[i] * h) * v.segment(b, e - b);
        });
        for (int j = 0; j < i; ++j) {
          cv[j] = h * T.A(i, j);
          cq[j] = h * h * T.AA(i, j);
        }
        combine(Vk, v, cv.data(), Qk, Q, cq.data(), alpha, i, team);
        eq.begin_stage(Qk.data(), Vk.data(), hg);
        alpha[i] = alpha[i - 1];  // predictor (extrapolations measured no better)
        eta = std::pow(std::max(eta, 1e-16), 0.8);
        // A stage that does not converge with the matrix of the step's middle gets one more try
        // with S set up at its own iterate (from there, or from the predictor if the iteration
        // diverged) before the step is cut 4-fold, or a fixed step fails (docs/performance.md,
        // "Newton's matrix at the stage").
        bool diverged = false;
        converged = newton_stage(i, ti, hg, diverged);
        if (!converged && !nonfinite) {
          if (diverged) alpha[i] = alpha[i - 1];
          stage_values(i, hg);
          ++st.factorizations;
          eta = 1.0;
          converged = eq.setup_newton(ti, Q.data(), V.data(), hg) && newton_stage(i, ti, hg, diverged);
        }
      }
      if (!converged) {  // with a fresh matrix: cut the step
        ++st.newton_fails;
        if (o.fixed_step > 0) return fail("Newton iteration failed with the fixed step");
        h *= 0.25;
        eta = 1.0;
        last_rejected = true;
        continue;
      }

      // Solution (stiffly accurate: the last stage) and error estimate.
      VecX &q1 = Q, &v1 = V, &eqv = Qk, &evv = Vk;
      const int team = eq.team();
      for_team_parts(u, team, [&](long b, long e) {
        Q.segment(b, e - b) = Qk.segment(b, e - b) + (hg * hg) * alpha[s - 1].segment(b, e - b);  // q1
        V.segment(b, e - b) = Vk.segment(b, e - b) + hg * alpha[s - 1].segment(b, e - b);         // v1
        r.segment(b, e - b).setZero();  // (free until the next stage)
      });
      for (int j = 0; j < s; ++j) {
        cq[j] = h * h * T.eq[j];
        cv[j] = h * T.ev[j];
      }
      combine(eqv, r, cq.data(), evv, r, cv.data(), alpha, s, team);
      for (int i : eq.quasi_static()) eqv[i] = evv[i] = 0.0;  // quasi-static (Reduction::quasi_static)
      weights(q, v, &q1, &v1);
      const double err = std::max(wrms(eqv, evv, w), 1e-10);
      const double expo = 1.0 / (T.embedded_order + 1);
      if (!std::isfinite(err) || !q1.allFinite() || !v1.allFinite()) {  // NaN passes no test: cut the step
        nonfinite = true;
        ++st.newton_fails;
        if (o.fixed_step > 0) return fail("the solution is not finite with the fixed step");
        h *= 0.25;
        eta = 1.0;
        last_rejected = true;
        continue;
      }
      if (err > 1.0 && o.fixed_step <= 0) {
        ++st.error_test_fails;
        h *= std::max(kMinFactor, kSafety * std::pow(err, -expo));
        last_rejected = true;
        continue;
      }

      // Accepted: outputs inside (t, t + h], then advance. A step that lands on a stop ends exactly
      // there (t + (t_stop − t) rounds to t_stop but for the last bit; `until` must be met exactly).
      const double t1 = lands ? t_stop : t + h;
      const VecX& a1 = alpha[s - 1];
      double Wd1 = Wd, Wi1 = Wi;
      for (int j = 0; j < s; ++j) {
        Wd1 += h * T.b[j] * Ps[j].dissipation;
        Wi1 += h * T.b[j] * Ps[j].input;
      }
      const Power& P1 = Ps[s - 1];
      ++st.steps;
      ++steps_this_output;
      st.last_step = h;
      while (k_out <= n_out && t_output(k_out) <= t1 + 1e-12 * std::max(1.0, t1)) {
        if (eq.stop_requested()) return RunStatus::interrupted(eq.stop().signal());  // a long step may cover many outputs
        const double to = t_output(k_out);
        OutputSample smp;
        if (std::abs(to - t1) <= 1e-12 * std::max(1.0, t1)) {
          smp = eq.sample(t1, q1.data(), v1.data(), a1.data(), Wd1, Wi1);
        } else {
          // The integrator's continuous solution: quintic Hermite of q from (q, v, a) at both
          // ends, its derivatives for v and a (the accelerations of the solution, smooth in the
          // stiff modes the steps damp; the torques of prescribed joints follow from them).
          const double th = (to - t) / h;
          double H[6], dH[6], ddH[6];
          hermite5(th, H, dH, ddH);
          // Into the error estimate's and the residual's vectors, free until the next step (an
          // output's own three would be 0.14 kB per rfe above the integration's memory).
          VecX &qo = eqv, &vo = evv, &ao = r;
          qo.noalias() = H[0] * q + (H[1] * h) * v + (H[2] * h * h) * a + H[3] * q1 + (H[4] * h) * v1 + (H[5] * h * h) * a1;
          vo.noalias() = (dH[0] / h) * q + dH[1] * v + (dH[2] * h) * a + (dH[3] / h) * q1 + dH[4] * v1 + (dH[5] * h) * a1;
          ao.noalias() = (ddH[0] / (h * h)) * q + (ddH[1] / h) * v + ddH[2] * a + (ddH[3] / (h * h)) * q1 +
                         (ddH[4] / h) * v1 + ddH[5] * a1;
          smp = eq.sample(to, qo.data(), vo.data(), ao.data(), hermite3(th, h, Wd, P.dissipation, Wd1, P1.dissipation),
                          hermite3(th, h, Wi, P.input, Wi1, P1.input));
        }
        smp.steps = st.steps;
        smp.last_step = h;
        const bool emitted = emit(smp);
        eq.give_back(smp);
        if (!emitted) return emit.failure();
        t_reached = to;
        ++k_out;
        steps_this_output = attempts_this_output = 0;
      }
      t = t1;
      for_team_parts(u, eq.team(), [&](long b, long e) {
        q.segment(b, e - b) = q1.segment(b, e - b);
        v.segment(b, e - b) = v1.segment(b, e - b);
        a.segment(b, e - b) = a1.segment(b, e - b);
      });
      P = P1;
      Wd = Wd1;
      Wi = Wi1;

      // Next step: PI controller (Gustafsson), no growth right after a rejection. A step cut short
      // by the caller's `until` keeps the size the controller had in mind.
      double fac = kSafety * std::pow(err, -0.7 * expo) * std::pow(err_prev, 0.4 * expo);
      fac = std::clamp(fac, kMinFactor, last_rejected ? 1.0 : kMaxFactor);
      err_prev = err;
      last_rejected = nonfinite = false;
      h = o.fixed_step > 0 ? o.fixed_step : (callers ? std::max(h, h_proposed) : h) * fac;
      if (o.max_step > 0) h = std::min(h, o.max_step);
      sample_due();
      // (A digital law's held values are the laws' own memory: the run's book checkpoints them.)
      if (emit.checkpoint_due()) {  // the state's vectors lent, not copied (0.14 kB per rfe)
        IntegratorState x = state_scalars();
        lend(x);
        const bool saved = emit.checkpoint(x);
        lend(x);  // (back)
        if (!saved) return emit.failure();
      }
    }
  } catch (const SamplerFailure& e) {
    return RunStatus::failed(e.what());
  } catch (const std::exception& e) {
    return fail(e.what());
  }
  if (k_out > n_out) {
    t_reached = o.t_end;
    return RunStatus::completed();
  }
  return RunStatus{};
}

EsdirkStepper::EsdirkStepper(EquationsOfMotion& eq, const IntegratorOptions& opts)
    : impl_(std::make_unique<Impl>(eq, opts)) {}
EsdirkStepper::~EsdirkStepper() = default;
EsdirkStepper::EsdirkStepper(EsdirkStepper&&) noexcept = default;

RunStatus EsdirkStepper::start(SampleEmitter& emit) {
  RFEM_CHECK_ARGUMENT(!impl_->started, "the stepper has started already");
  return impl_->start(emit);
}

RunStatus EsdirkStepper::advance(double until, SampleEmitter& emit) {
  RFEM_CHECK_ARGUMENT(impl_->started, "start() first");
  RFEM_CHECK_ARGUMENT(until >= impl_->t && until <= impl_->o.t_end, "until must lie in [t, t_end]");
  return impl_->advance(until, emit);
}

void EsdirkStepper::inputs_changed() {
  Impl& m = *impl_;
  RFEM_CHECK_ARGUMENT(m.started, "start() first");
  // The accelerations and powers at t from the new inputs (right limit): the next step's first
  // stage and the outputs' interpolation start from them.
  m.inputs_changed_here();
}

void EsdirkStepper::add_sampler(Sampler s) {
  RFEM_CHECK_ARGUMENT(s.period > 0 && std::isfinite(s.period) && s.next >= 0 && s.sample, "a sampler needs a period and a function");
  impl_->samplers.push_back(std::move(s));
}

double EsdirkStepper::time() const { return impl_->t; }
double EsdirkStepper::t_reached() const { return impl_->t_reached; }
const IntegratorStats& EsdirkStepper::stats() const { return impl_->st; }

IntegratorState EsdirkStepper::state() const { return impl_->state(); }

IntegratorState EsdirkStepper::Impl::state() const {
  IntegratorState x = state_scalars();
  x.q = q;
  x.v = v;
  x.a = a;
  return x;
}

IntegratorState EsdirkStepper::Impl::state_scalars() const {
  const Impl& m = *this;
  IntegratorState x;
  x.t = m.t;
  x.h = m.h;
  x.err_prev = m.err_prev;
  x.eta = m.eta;
  x.dissipated = m.Wd;
  x.input_work = m.Wi;
  x.power = m.P;
  x.next_output = m.k_out;
  x.stats = m.st;
  return x;
}

}  // namespace rfem
