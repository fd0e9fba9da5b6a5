#include "inputs.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include "../assembly/assemble.hpp"
#include "../results/reader.hpp"
#include "../solvers/run_status.hpp"

namespace rfem {

namespace {

// Joint torques of an earlier run: dataset joint_tau of group `run`, column `joint`, as a cubic
// spline through the output samples (error O(Δt⁴)); the run must reach this case's t_end. Every
// shape is checked: the file may come from anywhere.
std::shared_ptr<TorqueLaw> torque_from_results(const InputSpec& in, int joint, double t_end, const Warnings& warn) {
  std::unique_ptr<ResultsReader> f;
  try {
    f = std::make_unique<ResultsReader>(in.file);
  } catch (const ResultsError&) {
    throw CaseError(in.where + ".file: '" + in.file + "' is not a readable HDF5 results file");
  }
  if (!f->has(in.run + "/time") || !f->has(in.run + "/joint_tau")) {
    // has() is false also where damage stops HDF5 on the way: an object its group lists, unreadable.
    auto damaged = [&](const std::string& group, const std::string& name) {
      const std::string object = group == "/" ? name : group + "/" + name;
      if (f->has(object)) return false;
      try {
        const std::vector<std::string> names = f->children(group);
        return std::find(names.begin(), names.end(), name) != names.end();
      } catch (const ResultsError&) {
        return true;  // (the group exists: has() said so, or it is the root)
      }
    };
    for (const auto& [group, name] : {std::pair<std::string, std::string>{"/", in.run}, {in.run, "time"}, {in.run, "joint_tau"}})
      if ((group == "/" || f->has(group)) && damaged(group, name))
        throw CaseError(in.where + ".file: '" + in.file + "' is damaged: '" + (group == "/" ? name : group + "/" + name) +
                        "' cannot be read");
    throw CaseError(in.where + ".run: no run '" + in.run + "' with time and joint_tau in '" + in.file + "'");
  }
  Table t, tau;
  try {
    t = f->table(in.run + "/time");
    tau = f->table(in.run + "/joint_tau");
  } catch (const ResultsError& e) {
    throw CaseError(in.where + ".run: " + e.what());
  }
  const std::string status = f->attribute(in.run, "status", "unknown");
  const std::string source = "the run '" + in.run + "' in '" + in.file + "'";
  if (t.cols != 1) throw CaseError(in.where + ": " + source + ": time has " + std::to_string(t.cols) + " columns, not 1");
  if (tau.rows != t.rows)
    throw CaseError(in.where + ": " + source + " has " + std::to_string(t.rows) + " times but " + std::to_string(tau.rows) +
                    " rows of joint_tau");
  const int col = (in.joint > 0 ? in.joint : joint + 1) - 1;
  if (col >= tau.cols) throw CaseError(in.where + ".joint: the run has " + std::to_string(tau.cols) + " joints");
  if (t.rows < 3) throw CaseError(in.where + ": " + source + " has fewer than 3 output steps");
  const std::vector<double> times = t.column(0), values = tau.column(col);
  for (long i = 0; i < t.rows; ++i) {
    if (!std::isfinite(times[i]) || !std::isfinite(values[i]))
      throw CaseError(in.where + ": " + source + ": output " + std::to_string(i + 1) + " is not finite");
    if (i > 0 && !(times[i] > times[i - 1]))
      throw CaseError(in.where + ": " + source + ": its times do not increase at output " + std::to_string(i + 1));
  }
  if (t_end > times.back() * (1 + 1e-12) + 1e-12)
    throw CaseError(in.where + ": " + source + " ends at t = " + fmt::format("{}", times.back()) + " s (" + status +
                    "), before simulation.t_end = " + fmt::format("{}", t_end) + " s");
  if (!RunStatus::parse(status).is_completed() && warn)
    warn(fmt::format("{}: the source run '{}' did not complete ({}); its torques are used up to t = {} s", in.where, in.run,
                     status, times.back()));
  return spline_torque(times, values);
}

// A table's rows, which must cover the run (0 … t_end): tables are never extrapolated.
void read_table(const InputSpec& in, double t_end, std::vector<double>& t, std::vector<double>& v) {
  read_csv_series(in.file, t, v);
  if (t.front() > 0.0 || t.back() < t_end * (1 - 1e-12))
    throw CaseError(in.where + ".file: '" + in.file + "' covers t = " + fmt::format("{}", t.front()) + " … " +
                    fmt::format("{}", t.back()) + " s; the run needs 0 … " + fmt::format("{}", t_end) +
                    " s (a table is not extrapolated)");
}

// A prescribed motion of one of the motion kinds, starting from the joint's value q0.
std::shared_ptr<MotionLaw> motion_law(const InputSpec& in, double q0, double t_end) {
  switch (in.kind) {
    case InputKind::Deployment: return deployment_law(q0, in.alpha, in.T);
    case InputKind::Spinup: return spinup_law(q0, in.Omega, in.T);
    case InputKind::ConstantRate: return constant_rate_law(q0, in.rate);
    default: break;
  }
  std::vector<double> t, q;
  read_table(in, t_end, t, q);
  return tabulated_motion(t, q);
}

std::vector<double> all_breakpoints(const std::vector<JointInput>& laws) {
  std::vector<double> b;
  for (const auto& l : laws) {
    const auto x = l.breakpoints();
    b.insert(b.end(), x.begin(), x.end());
  }
  return b;
}

}  // namespace

std::vector<JointInput> joint_inputs(const Case& cs, const Warnings& warn) {
  std::vector<JointInput> out(cs.joints.size());
  std::vector<std::shared_ptr<MotionLaw>> reference(cs.joints.size());  // of PD joints
  bool rigid_ff = false;
  const double t_end = cs.has_simulation ? cs.sim.options.t_end : 0.0;
  for (size_t j = 0; j < cs.joints.size(); ++j) {
    const InputSpec& in = cs.inputs[j];
    const double q0 = cs.joint_values[static_cast<long>(j)], v0 = cs.joint_rates[static_cast<long>(j)];
    JointInput& ji = out[j];
    ji.q0 = q0;
    ji.v0 = v0;
    try {
      if (in.prescribed()) ji.motion = motion_law(in, q0, t_end);
      else if (in.kind == InputKind::Torque) ji.torque = constant_torque(in.value);
      else if (in.kind == InputKind::TorqueTable) {
        std::vector<double> t, tau;
        read_table(in, t_end, t, tau);
        ji.torque = tabulated_torque(t, tau);
      } else if (in.kind == InputKind::TorqueFromRun) {
        ji.torque = torque_from_results(in, static_cast<int>(j), t_end, warn);
      } else if (in.kind == InputKind::Pd) {
        reference[j] = motion_law(*in.reference, q0, t_end);
        ji.torque = pd_law(reference[j], in.kp, in.kd, nullptr);
        rigid_ff |= in.feedforward == Feedforward::Rigid;
      }
    } catch (const CaseError&) {
      throw;
    } catch (const std::exception& e) {
      throw CaseError(in.where + ": " + e.what());
    }
    if (ji.motion) {  // a prescribed joint starts on its law
      ji.q0 = ji.motion->at(0.0).q;
      ji.v0 = ji.motion->at(0.0).qd;
    }
  }
  if (rigid_ff) {
    // Computed torque: the rigid manipulator's inverse dynamics along every joint's motion or
    // reference, so every joint needs one.
    std::vector<JointInput> laws(out.size());
    for (size_t j = 0; j < out.size(); ++j) {
      laws[j].motion = out[j].motion ? out[j].motion : reference[j];
      if (!laws[j].motion)
        throw CaseError(cs.inputs[j].where + ": feedforward = \"rigid\" needs a motion or a PD reference on every joint");
    }
    const std::vector<JointInput> ff = rigid_torque_inputs(std::make_shared<const Model>(rigidify(build_model(cs))), laws);
    for (size_t j = 0; j < out.size(); ++j) {
      const InputSpec& in = cs.inputs[j];
      if (in.kind != InputKind::Pd || in.feedforward != Feedforward::Rigid) continue;
      out[j].torque = pd_law(reference[j], in.kp, in.kd, ff[j].torque);
    }
  }
  for (size_t j = 0; j < out.size(); ++j)  // digital PD laws: sampled, held
    if (const InputSpec& in = cs.inputs[j]; in.kind == InputKind::Pd && in.sample_time > 0) {
      if (cs.sim.options.kind == IntegratorKind::Bdf)
        throw CaseError(in.where + ".sample_time: a sampled law needs simulation.integrator = \"esdirk\" (its steps end at the samples)");
      out[j].torque = sampled_law(out[j].torque, in.sample_time, in.delay);
    }
  return out;
}

std::vector<JointInput> rigid_torque_inputs(std::shared_ptr<const Model> rigid, const std::vector<JointInput>& laws) {
  if (!rigid) throw std::invalid_argument("rigid_torque_inputs: no model");
  if (rigid->n() != 0) throw std::invalid_argument("rigid_torque_inputs: the model must be rigid (rigidify it)");
  if (static_cast<int>(laws.size()) != rigid->m())
    throw std::invalid_argument("rigid_torque_inputs: one law per joint is required (" + std::to_string(rigid->m()) + ")");
  for (const JointInput& l : laws)
    if (!l.motion) throw std::invalid_argument("rigid_torque_inputs: every joint needs a motion law");
  // The joints' laws share the inverse dynamics at the last time asked: a residual asks every joint
  // at one time, and a stage's Newton iterations ask at the same time again. (Locked: two runs may
  // share these inputs.)
  struct Last {
    explicit Last(const Model& rigid) : ws(rigid) {}
    std::mutex m;
    double t = std::numeric_limits<double>::quiet_NaN();
    VecX F;
    Workspace ws;  // the inverse dynamics' scratch, bound to the rigid model
  };
  const auto last = std::make_shared<Last>(*rigid);
  std::vector<JointInput> out(laws.size());
  for (size_t j = 0; j < laws.size(); ++j) {
    out[j].q0 = laws[j].q0;
    out[j].v0 = laws[j].v0;
    out[j].torque = torque_function([rigid, laws, j, last](double t) {
      const std::lock_guard<std::mutex> lock(last->m);
      if (!(last->t == t)) {
        const int m = rigid->m();
        VecX q(m), v(m), a(m);
        for (int i = 0; i < m; ++i) {
          const MotionSample s = laws[i].motion->at(t);
          q[i] = s.q;
          v[i] = s.qd;
          a[i] = s.qdd;
        }
        generalised_forces(*rigid, q, v, a, ForceTerms{}, last->F, nullptr, &last->ws);
        last->t = t;
      }
      return last->F[static_cast<long>(j)];
    }, all_breakpoints(laws));
  }
  return out;
}

std::vector<std::string> input_kinds(const std::vector<JointInput>& inputs) {
  std::vector<std::string> kinds;
  for (const auto& in : inputs)
    kinds.push_back(in.prescribed() ? "motion"
                    : (in.torque->stiffness() != 0.0 || in.torque->damping() != 0.0) ? "feedback" : "torque");
  return kinds;
}

}  // namespace rfem
