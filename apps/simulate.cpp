#include <fmt/core.h>
#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <csignal>
#include <cmath>

#include "apps/simulate.hpp"
#include "apps/progress.hpp"
#include "apps/results_file.hpp"
#include "solvers/integrator.hpp"

namespace rfem::app {

namespace {

std::atomic<int> g_stop{0};
extern "C" void on_signal(int sig) { g_stop.store(sig); }

// Joint torques of an earlier run: dataset joint_tau of group `run`, column `joint`.
std::shared_ptr<TorqueLaw> torque_from_results(const InputSpec& in, int joint) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(in.file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) throw CaseError(in.where + ".file: '" + in.file + "' is not a readable HDF5 results file");
  auto read = [&](const std::string& name, std::vector<double>& out, hsize_t& rows, hsize_t& cols) {
    const hid_t d = H5Dopen2(f, (in.run + "/" + name).c_str(), H5P_DEFAULT);
    if (d < 0) return false;
    const hid_t s = H5Dget_space(d);
    hsize_t dims[2] = {0, 1};
    H5Sget_simple_extent_dims(s, dims, nullptr);
    rows = dims[0];
    cols = dims[1];
    out.resize(rows * cols);
    const bool ok = H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()) >= 0;
    H5Sclose(s);
    H5Dclose(d);
    return ok;
  };
  std::vector<double> t, tau;
  hsize_t rt = 0, ct = 0, rj = 0, cj = 0;
  const bool ok = read("time", t, rt, ct) && read("joint_tau", tau, rj, cj);
  H5Fclose(f);
  if (!ok) throw CaseError(in.where + ".run: no run '" + in.run + "' with time and joint_tau in '" + in.file + "'");
  const int col = (in.joint > 0 ? in.joint : joint + 1) - 1;
  if (col >= static_cast<int>(cj)) throw CaseError(in.where + ".joint: the run has " + std::to_string(cj) + " joints");
  std::vector<double> v(rj);
  for (hsize_t i = 0; i < rj; ++i) v[i] = tau[i * cj + col];
  t.resize(rt);
  return tabulated_torque(t, v);
}

}  // namespace

std::vector<JointInput> joint_inputs(const Case& cs) {
  std::vector<JointInput> out(cs.joints.size());
  for (size_t j = 0; j < cs.joints.size(); ++j) {
    const InputSpec& in = cs.inputs[j];
    const double q0 = cs.joint_values[static_cast<long>(j)], v0 = cs.joint_rates[static_cast<long>(j)];
    JointInput& ji = out[j];
    ji.q0 = q0;
    ji.v0 = v0;
    try {
      if (in.kind == "deployment") ji.motion = deployment_law(q0, in.alpha, in.T);
      else if (in.kind == "spinup") ji.motion = spinup_law(q0, in.Omega, in.T);
      else if (in.kind == "constant_rate") ji.motion = constant_rate_law(q0, in.rate);
      else if (in.kind == "table") {
        std::vector<double> t, q;
        read_csv_series(in.file, t, q);
        ji.motion = tabulated_motion(t, q);
      } else if (in.kind == "torque") ji.torque = constant_torque(in.value);
      else if (in.kind == "torque_table") {
        std::vector<double> t, tau;
        read_csv_series(in.file, t, tau);
        ji.torque = tabulated_torque(t, tau);
      } else if (in.kind == "torque_from_run") ji.torque = torque_from_results(in, static_cast<int>(j));
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
  return out;
}

namespace {


RunSummary run_one(ResultsFile& file, const std::string& name, const Model& model, const std::vector<JointInput>& inputs,
                   const Case& cs, bool quiet, const Observer& observe) {
  Progress progress(name, cs.sim.t_end, quiet);
  RunSummary s;
  s.name = name;
  RunGroup group(file, name, model, cs.sim.flexible_every);
  IntegratorOptions o;
  o.t_end = cs.sim.t_end;
  o.output_dt = cs.sim.output_dt;
  o.rtol = cs.sim.rtol;
  o.atol = cs.sim.atol;
  o.atol_velocity = cs.sim.atol_velocity;
  o.max_step = cs.sim.max_step;
  o.max_order = cs.sim.max_order;
  o.max_steps = cs.sim.max_steps;
  double balance0 = NAN;
  const auto t0 = std::chrono::steady_clock::now();
  const RunOutcome r = integrate(
      model, inputs, o,
      [&](const OutputSample& x) {
        group.append(x);
        if (observe) observe(name, model, x);
        progress.update(x.t, x.steps);
        spdlog::debug("{}: output t = {:.6g} s, {} steps, last step {:.3g} s", name, x.t, x.steps, x.last_step);
        const Eigen::Vector3d u = tip_deflection(model, x.q);
        s.peak_u1 = std::max(s.peak_u1, std::abs(u[0]));
        s.peak_u2 = std::max(s.peak_u2, std::abs(u[1]));
        s.peak_theta = std::max(s.peak_theta, std::abs(u[2]));
        const double bal = x.energy.kinetic + x.energy.elastic + x.energy.gravity + x.dissipated - x.input_work;
        if (std::isnan(balance0)) balance0 = bal;
        s.energy_drift = std::max(s.energy_drift, std::abs(bal - balance0));
        s.energy_scale = std::max({s.energy_scale, x.energy.kinetic, std::abs(x.energy.elastic), std::abs(x.input_work)});
      },
      &g_stop);
  s.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  progress.finish();
  s.status = r.status;
  s.completed = r.completed;
  s.stats = r.stats;
  s.t_reached = r.t_reached;
  s.samples = group.samples();
  group.attribute("status", r.status);
  group.attribute("wall_time_s", s.wall);
  group.attribute("t_reached", r.t_reached);
  group.attribute("rtol", o.rtol);
  group.attribute("atol", o.atol);
  group.attribute("atol_velocity", o.atol_velocity);
  group.attribute("max_step", o.max_step);
  group.attribute("max_order", static_cast<double>(o.max_order));
  group.attribute("output_dt", o.output_dt);
  group.attribute("threads", static_cast<double>(omp_get_max_threads()));
  group.attribute("steps", static_cast<double>(r.stats.steps));
  group.attribute("residual_evals", static_cast<double>(r.stats.residual_evals));
  group.attribute("factorizations", static_cast<double>(r.stats.factorizations));
  group.attribute("newton_iters", static_cast<double>(r.stats.newton_iters));
  group.attribute("newton_fails", static_cast<double>(r.stats.newton_fails));
  group.attribute("error_test_fails", static_cast<double>(r.stats.error_test_fails));
  std::string kinds;
  for (const auto& in : inputs) kinds += std::string(kinds.empty() ? "" : ",") + (in.prescribed() ? "motion" : "torque");
  group.attribute("inputs", kinds);
  if (!quiet)
    fmt::print("{:<10} {}: t = {:.3f} s, {} outputs, wall {:.3f} s; steps {}, residuals {}, factorisations {}, "
               "Newton iterations {} (failures {}), error-test failures {}\n"
               "{:<10} peak |u1| = {:.6e} m, |u2| = {:.6e} m, |theta| = {:.6e} rad; energy balance drift {:.3e} J "
               "(scale {:.3e} J)\n",
               name, r.status, r.t_reached, s.samples, s.wall, r.stats.steps, r.stats.residual_evals,
               r.stats.factorizations, r.stats.newton_iters, r.stats.newton_fails, r.stats.error_test_fails, "",
               s.peak_u1, s.peak_u2, s.peak_theta, s.energy_drift, s.energy_scale);
  return s;
}

}  // namespace

// Force input reproducing the rigid manipulator's inverse dynamics of the given laws (paper step 2).
std::vector<JointInput> rigid_torque_inputs(const Model& rigid, const std::vector<JointInput>& laws) {
  std::vector<JointInput> out(laws.size());
  for (size_t j = 0; j < laws.size(); ++j) {
    out[j].q0 = laws[j].q0;
    out[j].v0 = laws[j].v0;
    out[j].torque = torque_function([&rigid, laws, j](double t) {
      const int m = rigid.m();
      VecX q(m), v(m), a(m), F;
      for (int i = 0; i < m; ++i) {
        const MotionSample s = laws[i].motion->at(t);
        q[i] = s.q;
        v[i] = s.qd;
        a[i] = s.qdd;
      }
      generalised_forces(rigid, q, v, a, ForceTerms{}, F);
      return F[static_cast<long>(j)];
    });
  }
  return out;
}

std::atomic<int>& stop_flag() { return g_stop; }

void install_signal_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

std::vector<RunSummary> simulate_case(const Case& cs, const Model& model, const std::vector<JointInput>& inputs,
                                      ResultsFile& file, const std::string& prefix, bool quiet, const Observer& observe) {
  std::vector<RunSummary> runs;
  if (cs.sim.procedure == "paper") {
    for (size_t j = 0; j < inputs.size(); ++j)
      if (!inputs[j].prescribed())
        throw CaseError(cs.inputs[j].where + ": the paper procedure needs a motion law on every joint");
    const Model rigid = rigidify(model);
    runs.push_back(run_one(file, prefix + "rigid", rigid, inputs, cs, quiet, observe));
    if (runs.back().completed) runs.push_back(run_one(file, prefix + "kinematic", model, inputs, cs, quiet, observe));
    if (runs.back().completed)
      runs.push_back(run_one(file, prefix + "force", model, rigid_torque_inputs(rigid, inputs), cs, quiet, observe));
  } else {
    runs.push_back(run_one(file, prefix + "run", model, inputs, cs, quiet, observe));
  }
  file.flush();
  return runs;
}

}  // namespace rfem::app
