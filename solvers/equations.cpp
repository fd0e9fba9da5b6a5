#include "equations.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <chrono>
#include <stdexcept>
#include <string>

#include "../core/check.hpp"
#include "mass_solve.hpp"
#include "statics.hpp"
#include "team_parts.hpp"

namespace rfem {

VecX initial_joint_values(const Model& model, const std::vector<JointInput>& inputs) {
  RFEM_CHECK_ARGUMENT_SIZE(inputs.size(), model.m(), "inputs");
  VecX qb(model.m());
  for (int j = 0; j < model.m(); ++j) qb[j] = inputs[j].prescribed() ? inputs[j].motion->at(0.0).q : inputs[j].q0;
  return qb;
}

namespace {
const Model& checked(const std::shared_ptr<const Model>& m) {
  if (!m) throw std::invalid_argument("EquationsOfMotion: no model");
  return *m;
}
}  // namespace

EquationsOfMotion::EquationsOfMotion(std::shared_ptr<const Model> model_ptr, std::vector<JointInput> inputs_in,
                                     const ForceTerms& terms, StopToken stop, LinearSolverKind solver,
                                     const Parallelism& parallel, bool keep_stiffness)
    : model_(std::move(model_ptr)),
      inputs_(std::move(inputs_in)),
      stop_(std::move(stop)),
      terms_(terms),
      governor_(checked(model_).n() >= parallel.min_rfes ? parallel.max_threads() : 1, parallel.threads > 0),
      damped_(model_->sdes_damped() ||
              std::any_of(model_->joints.begin(), model_->joints.end(),
                          [](const Joint& j) { return j.drive.damping > 0 || j.drive.friction > 0; })) {
  const Model& model = *model_;
  const std::vector<JointInput>& inputs = inputs_;
  ws_.parallel = parallel;
  ws_.parallel.threads = governor_.threads();
  ws_.bind(model);  // (checked against the model at every kernel call)
  RFEM_CHECK_ARGUMENT_SIZE(inputs.size(), model.m(), "inputs (one per joint)");
  for (int j = 0; j < model.m(); ++j)
    RFEM_CHECK_ARGUMENT(inputs[j].motion || inputs[j].torque,
                        "joint " + std::to_string(j + 1) + " has neither a motion law nor a torque law");
  const int n6 = model.flexible_dofs();
  for (int i = 0; i < n6; ++i) unknown_.push_back(i);  // a prefix in order: expand() copies it as a block
  base_col_.assign(model.m(), -1);
  for (int j = 0; j < model.m(); ++j)
    if (!inputs[j].prescribed()) {
      base_col_[j] = static_cast<int>(unknown_.size());
      unknown_.push_back(model.joint_index(j));
    }
  nu_ = static_cast<int>(unknown_.size());
  ubase_col_ = base_col_;
  reduction_ = Reduction::of(model, initial_joint_values(model, inputs), parallel);
  if (reduction_) {
    nu_ = reduction_->rfe() + (nu_ - n6);
    for (int& c : ubase_col_)
      if (c >= 0) c += reduction_->rfe() - n6;
  }
  newton_ = std::make_unique<NewtonSystem>(model_, base_col_, solver, keep_stiffness, reduction_);
  std::vector<double> kp, kd;  // feedback laws stiffen and damp their joints (in column order)
  bool feedback = false;
  for (int j = 0; j < model.m(); ++j)
    if (!inputs[j].prescribed()) {
      kp.push_back(inputs[j].torque->stiffness());
      kd.push_back(inputs[j].torque->damping());
      feedback |= kp.back() != 0.0 || kd.back() != 0.0;
    }
  if (feedback) newton_->set_joint_feedback(std::move(kp), std::move(kd));
}

void EquationsOfMotion::expand(double t, const double* qu, const double* vu, const double* au) {
  RFEM_CHECK_ARGUMENT(unknowns() == 0 || (qu && vu), "qu and vu must point to unknowns() values");
  if (reduction_) {  // the full unknowns first: q0 + P q_u, P v_u, P a_u
    const int U = static_cast<int>(unknown_.size()), k = U - model_->flexible_dofs();
    qf_.resize(U);
    vf_.resize(U);
    af_.resize(U);
    if (in_stage_ && au)
      reduction_->lift_stage(qu, vu, au, qkf_.data(), vkf_.data(), stage_hg_, qf_.data(), vf_.data(), af_.data(), k, team());
    else
      reduction_->lift_state(qu, vu, au, qf_.data(), vf_.data(), af_.data(), k, team());
    qu = qf_.data();
    vu = vf_.data();
    au = au ? af_.data() : nullptr;
  }
  // Every coordinate is set below: the rfes' are the first unknowns, in order (the constructor), and
  // every joint is either prescribed or unknown.
  const int N = model_->dof(), u = static_cast<int>(unknown_.size()), n6 = model_->flexible_dofs();
  q_.resize(N);
  v_.resize(N);
  a_.resize(N);
  for_team_parts(n6, team(), [&](long b, long e) {
    q_.segment(b, e - b) = Eigen::Map<const VecX>(qu + b, e - b);
    v_.segment(b, e - b) = Eigen::Map<const VecX>(vu + b, e - b);
    if (au) a_.segment(b, e - b) = Eigen::Map<const VecX>(au + b, e - b);
    else a_.segment(b, e - b).setZero();
  });
  if (!au) a_.tail(N - n6).setZero();
  for (int i = n6; i < u; ++i) {
    q_[unknown_[i]] = qu[i];
    v_[unknown_[i]] = vu[i];
    a_[unknown_[i]] = au ? au[i] : 0.0;
  }
  for (int j = 0; j < model_->m(); ++j)
    if (inputs_[j].prescribed()) {
      const MotionSample s = inputs_[j].motion->at(t);
      const int k = model_->joint_index(j);
      q_[k] = s.q;
      v_[k] = s.qd;
      a_[k] = s.qdd;
    }
}

VecX EquationsOfMotion::torques(double t) const {
  VecX tau(model_->m());
  for (int j = 0; j < model_->m(); ++j)
    tau[j] = inputs_[j].prescribed() ? F_[model_->joint_index(j)]
                                     : inputs_[j].torque->at(t, q_[model_->joint_index(j)], v_[model_->joint_index(j)]);
  return tau;
}

Power EquationsOfMotion::residual(double t, const double* qu, const double* vu, const double* au, double* r) {
  RFEM_CHECK_ARGUMENT(unknowns() == 0 || r, "r must point to unknowns() values");
  VecX tau;
  const Power p = forces(t, qu, vu, au, tau);
  const int u = static_cast<int>(unknown_.size()), m = model_->m();
  const int n6 = model_->flexible_dofs();  // the first unknowns, in order
  if (reduction_) rf_.resize(u);
  double* full = reduction_ ? rf_.data() : r;
  for_team_parts(n6, team(), [&](long b, long e) { Eigen::Map<VecX>(full + b, e - b) = F_.segment(b, e - b); });
  for (int i = n6; i < u; ++i) full[i] = F_[unknown_[i]];
  for (int j = 0; j < m; ++j)
    if (base_col_[j] >= 0) full[base_col_[j]] -= tau[j];
  if (reduction_) reduction_->project(full, r, u - n6, team());  // Galerkin: r_η = Φᵀ r_l
  return p;
}

void EquationsOfMotion::begin_stage(const double* Qk, const double* Vk, double hg) {
  RFEM_CHECK_ARGUMENT(unknowns() == 0 || (Qk && Vk), "Qk and Vk must point to unknowns() values");
  stage_hg_ = hg;
  if (!reduction_) return;
  const int U = static_cast<int>(unknown_.size()), k = U - model_->flexible_dofs();
  qkf_.resize(U);
  vkf_.resize(U);
  reduction_->lift_state(Qk, Vk, nullptr, qkf_.data(), vkf_.data(), nullptr, k, team());
}

Power EquationsOfMotion::stage_residual(double t, const double* Q, const double* V, const double* A, double* r) {
  RFEM_CHECK_ARGUMENT(!reduction_ || qkf_.size() == static_cast<long>(unknown_.size()), "stage_residual before begin_stage");
  struct Stage {  // (reset on every exit)
    bool& on;
    explicit Stage(bool& b) : on(b) { on = true; }
    ~Stage() { on = false; }
  } stage(in_stage_);
  return residual(t, Q, V, A, r);
}

Power EquationsOfMotion::forces(double t, const double* qu, const double* vu, const double* au, VecX& tau) {
  const auto start = std::chrono::steady_clock::now();
  expand(t, qu, vu, au);
  Power p;
  generalised_forces(*model_, q_, v_, a_, terms_, F_, damped_ ? &p.dissipation : nullptr, &ws_);
  if (!by_steps_) {
    governor_.record(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    ws_.parallel.threads = governor_.threads();
  }
  tau = torques(t);
  p.input = tau.dot(model_->joint_coords(v_));
  return p;
}

Power EquationsOfMotion::power_change(double t, const double* vu, const VecX& da, double hg) {
  RFEM_CHECK_ARGUMENT(unknowns() == 0 || vu, "vu must point to unknowns() values");
  RFEM_CHECK_ARGUMENT_SIZE(da.size(), unknowns(), "da");
  Power d;
  const MatX& rows = newton_->base_rows();
  for (int j = 0; j < model_->m(); ++j) {
    if (inputs_[j].prescribed()) d.input += inputs_[j].motion->at(t).qd * rows.row(j).dot(da);
    else {  // P = τ(t, q, v) v with δv = hγ δa, δq = (hγ)² δa
      const TorqueLaw& law = *inputs_[j].torque;
      const double vj = vu[ubase_col_[j]], dq = hg * hg * da[ubase_col_[j]], dv = hg * da[ubase_col_[j]];
      d.input += law.at(t, q_[model_->joint_index(j)], vj) * dv - (law.stiffness() * dq + law.damping() * dv) * vj;
    }
  }
  if (model_->sdes_damped()) {  // the Newton system keeps the sdes' C only then
    VecX Cda;
    newton_->damping_times(da, Cda);
    d.dissipation = 2.0 * hg * Eigen::Map<const VecX>(vu, unknowns()).dot(Cda);
  }
  for (int j = 0; j < model_->m(); ++j)  // the drives' power, not a quadratic form when they have friction
    if (ubase_col_[j] >= 0) d.dissipation += model_->joints[j].drive.power_derivative(vu[ubase_col_[j]]) * hg * da[ubase_col_[j]];
  return d;
}

VecX EquationsOfMotion::accelerations(double t, const double* qu, const double* vu) {
  const int u = unknowns();
  VecX rhs(u);
  residual(t, qu, vu, nullptr, rhs.data());
  rhs = -rhs;
  if (!newton_->solve_mass(q_, v_, rhs, mass_values_, ws_))
    throw std::runtime_error("the mass matrix is not positive definite at t = " + std::to_string(t) + " s");
  std::vector<double>().swap(mass_values_);  // needed once or at output times: do not keep it
  return rhs;
}

OutputSample EquationsOfMotion::sample(double t, const double* qu, const double* vu, const double* au,
                                       double dissipated, double input_work) {
  VecX a_own;
  if (!au && unknowns() > 0) {
    a_own = accelerations(t, qu, vu);
    au = a_own.data();
  }
  VecX tau;
  forces(t, qu, vu, au, tau);  // F at these accelerations: the required torques
  if (model_->free_base) {
    const double pitch = q_[model_->joint_index(free_base_pitch)];
    if (std::abs(pitch) > free_base_pitch_limit) {
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "the free base's pitch reached %.1f deg at t = %.6g s: its yaw-pitch-roll angles are singular "
                    "at +-90 deg (runs stop beyond +-%.0f deg)",
                    pitch * 180 / M_PI, t, free_base_pitch_limit * 180 / M_PI);
      throw std::runtime_error(buf);
    }
  }
  OutputSample s;
  s.t = t;
  s.tau = std::move(tau);
  s.energy = energies(*model_, q_, v_, &ws_);
  s.momentum = momentum(*model_, q_, v_, &ws_);
  s.dissipated = dissipated;
  s.input_work = input_work;
  // The full coordinates move into the sample (copies would be 0.14 kB per rfe above the run's
  // memory at every output); give_back returns them, and expand() sizes them again otherwise.
  s.q.swap(q_);
  s.v.swap(v_);
  s.a.swap(a_);
  return s;
}

void EquationsOfMotion::give_back(OutputSample& s) {
  if (q_.size() == 0) q_.swap(s.q);
  if (v_.size() == 0) v_.swap(s.v);
  if (a_.size() == 0) a_.swap(s.a);
}

void EquationsOfMotion::report_step(double seconds, long residuals) {
  if (residuals <= 0) return;
  governor_.record(seconds / residuals);
  ws_.parallel.threads = governor_.threads();
}

bool EquationsOfMotion::setup_newton(double t, const double* qu, const double* vu, double h) {
  RFEM_CHECK_ARGUMENT(h > 0 && std::isfinite(h), "the step h must be positive and finite");
  expand(t, qu, vu, nullptr);
  return newton_->setup(q_, v_, h, ws_);
}

std::vector<double> EquationsOfMotion::breakpoints(double t_end) const {
  std::vector<double> b;
  for (const auto& in : inputs_)
    for (double x : in.breakpoints())
      if (x > 0.0 && x < t_end) b.push_back(x);
  std::sort(b.begin(), b.end());
  b.erase(std::unique(b.begin(), b.end(), [](double x, double y) { return y - x <= 1e-12 * std::max(1.0, y); }), b.end());
  return b;
}

void EquationsOfMotion::initial_state(VecX& qu, VecX& vu, bool static_equilibrium) const {
  qu = VecX::Zero(static_cast<long>(unknown_.size()));  // the full unknowns, reduced at the end
  vu = VecX::Zero(static_cast<long>(unknown_.size()));
  const auto reduce = [&] {
    if (!reduction_) return;
    VecX q(nu_), v(nu_);
    const int k = static_cast<int>(unknown_.size()) - model_->flexible_dofs();
    reduction_->restrict(qu.data(), q.data(), k, true);
    reduction_->restrict(vu.data(), v.data(), k, false);
    qu = std::move(q);
    vu = std::move(v);
  };
  for (int j = 0; j < model_->m(); ++j)
    if (base_col_[j] >= 0) {
      qu[base_col_[j]] = inputs_[j].q0;
      vu[base_col_[j]] = inputs_[j].v0;
    }
  if (!static_equilibrium || model_->n() == 0) return reduce();
  VecX qb(model_->m()), vb(model_->m());
  for (int j = 0; j < model_->m(); ++j) {
    const bool law = inputs_[j].prescribed();
    qb[j] = law ? inputs_[j].motion->at(0.0).q : inputs_[j].q0;
    vb[j] = law ? inputs_[j].motion->at(0.0).qd : inputs_[j].v0;
  }
  StaticOptions so;
  so.parallel = ws_.parallel;  // (the run's threads, also here)
  so.reduction = reduction_.get();
  const StaticResult eq = solve_static(*model_, qb, vb, TipLoads{}, so);
  qu.head(model_->flexible_dofs()) = eq.q.head(model_->flexible_dofs());
  reduce();
}

const std::vector<int>& EquationsOfMotion::quasi_static() const {
  static const std::vector<int> none;
  return reduction_ ? reduction_->quasi_static() : none;
}

VecX EquationsOfMotion::full_coordinates(double t, const double* xu, int order) const {
  VecX x = VecX::Zero(model_->dof());
  VecX lifted;
  if (reduction_ && nu_ > 0) {
    lifted.resize(static_cast<long>(unknown_.size()));
    reduction_->lift(xu, lifted.data(), static_cast<int>(unknown_.size()) - model_->flexible_dofs(), order == 0);
    xu = lifted.data();
  }
  for (size_t i = 0; i < unknown_.size(); ++i) x[unknown_[i]] = xu[i];
  for (int j = 0; j < model_->m(); ++j)
    if (inputs_[j].prescribed()) {
      const MotionSample s = inputs_[j].motion->at(t);
      x[model_->joint_index(j)] = order == 0 ? s.q : order == 1 ? s.qd : s.qdd;
    }
  return x;
}

std::vector<std::string> EquationsOfMotion::unknown_names(const std::vector<std::string>& names) const {
  RFEM_CHECK_ARGUMENT_SIZE(names.size(), model_->dof(), "coordinate names");
  std::vector<std::string> out;
  if (reduction_) out = reduction_->names(*model_, names);
  else
    for (int i = 0; i < model_->flexible_dofs(); ++i) out.push_back(names[i]);
  for (size_t i = model_->flexible_dofs(); i < unknown_.size(); ++i) out.push_back(names[unknown_[i]]);
  return out;
}

}  // namespace rfem
