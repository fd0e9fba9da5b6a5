#include <fmt/core.h>
#include <fmt/ranges.h>
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

// Joint torques of an earlier run: dataset joint_tau of group `run`, column `joint`, as a cubic
// spline through the output samples (error O(Δt⁴)); the run must reach this case's t_end.
std::shared_ptr<TorqueLaw> torque_from_results(const InputSpec& in, int joint, double t_end) {
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
  std::string status = "unknown";
  if (ok) {  // the source's status attribute (variable-length string)
    const hid_t g = H5Oopen(f, in.run.c_str(), H5P_DEFAULT);
    if (g >= 0 && H5Aexists(g, "status") > 0) {
      const hid_t a = H5Aopen(g, "status", H5P_DEFAULT);
      const hid_t type = H5Aget_type(a);
      if (H5Tis_variable_str(type) > 0) {
        char* p = nullptr;
        if (H5Aread(a, type, &p) >= 0 && p) {
          status = p;
          H5free_memory(p);
        }
      }
      H5Tclose(type);
      H5Aclose(a);
    }
    if (g >= 0) H5Oclose(g);
  }
  H5Fclose(f);
  if (!ok) throw CaseError(in.where + ".run: no run '" + in.run + "' with time and joint_tau in '" + in.file + "'");
  const int col = (in.joint > 0 ? in.joint : joint + 1) - 1;
  if (col >= static_cast<int>(cj)) throw CaseError(in.where + ".joint: the run has " + std::to_string(cj) + " joints");
  t.resize(rt);
  if (rt < 3) throw CaseError(in.where + ": the run '" + in.run + "' in '" + in.file + "' has fewer than 3 output steps");
  if (t_end > t.back() * (1 + 1e-12) + 1e-12)
    throw CaseError(in.where + ": the run '" + in.run + "' in '" + in.file + "' ends at t = " + fmt::format("{}", t.back()) +
                    " s (" + status + "), before simulation.t_end = " + fmt::format("{}", t_end) + " s");
  if (status != "completed")
    fmt::print(stderr, "rfem: warning: {}: the source run '{}' did not complete ({}); its torques are used up to t = {} s\n",
               in.where, in.run, status, t.back());
  std::vector<double> v(rj);
  for (hsize_t i = 0; i < rj; ++i) v[i] = tau[i * cj + col];
  return spline_torque(t, v);
}

}  // namespace

namespace {
// A prescribed motion of one of the motion kinds, starting from the joint's value q0.
std::shared_ptr<MotionLaw> motion_law(const InputSpec& in, double q0) {
  if (in.kind == "deployment") return deployment_law(q0, in.alpha, in.T);
  if (in.kind == "spinup") return spinup_law(q0, in.Omega, in.T);
  if (in.kind == "constant_rate") return constant_rate_law(q0, in.rate);
  std::vector<double> t, q;
  read_csv_series(in.file, t, q);
  return tabulated_motion(t, q);
}
}  // namespace

std::vector<JointInput> joint_inputs(const Case& cs) {
  std::vector<JointInput> out(cs.joints.size());
  std::vector<std::shared_ptr<MotionLaw>> reference(cs.joints.size());  // of PD joints
  bool rigid_ff = false;
  for (size_t j = 0; j < cs.joints.size(); ++j) {
    const InputSpec& in = cs.inputs[j];
    const double q0 = cs.joint_values[static_cast<long>(j)], v0 = cs.joint_rates[static_cast<long>(j)];
    JointInput& ji = out[j];
    ji.q0 = q0;
    ji.v0 = v0;
    try {
      if (in.prescribed()) ji.motion = motion_law(in, q0);
      else if (in.kind == "torque") ji.torque = constant_torque(in.value);
      else if (in.kind == "torque_table") {
        std::vector<double> t, tau;
        read_csv_series(in.file, t, tau);
        ji.torque = tabulated_torque(t, tau);
      } else if (in.kind == "torque_from_run") {
        ji.torque = torque_from_results(in, static_cast<int>(j), cs.has_simulation ? cs.sim.options.t_end : 0.0);
      } else if (in.kind == "pd") {
        reference[j] = motion_law(*in.reference, q0);
        ji.torque = pd_law(reference[j], in.kp, in.kd, nullptr);
        rigid_ff |= in.feedforward == "rigid";
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
    const auto rigid = std::make_shared<const Model>(rigidify(build_model(cs)));
    const std::vector<JointInput> ff = rigid_torque_inputs(*rigid, laws);
    for (size_t j = 0; j < out.size(); ++j) {
      const InputSpec& in = cs.inputs[j];
      if (in.kind != "pd" || in.feedforward != "rigid") continue;
      const auto f = ff[j].torque;
      auto keep = torque_function([rigid, f](double t) { return f->at(t); }, f->breakpoints());  // rigid lives on
      out[j].torque = pd_law(reference[j], in.kp, in.kd, keep);
    }
  }
  return out;
}

namespace {


RunSummary run_one(ResultsFile& file, const std::string& name, const Model& model, const std::vector<JointInput>& inputs,
                   const Case& cs, bool quiet, const Observer& observe, int threads) {
  Progress progress(name, cs.sim.options.t_end, quiet);
  RunSummary s;
  s.name = name;
  for (const MountedLink& L : model.links) s.peaks.push_back({L.name});
  RunGroup group(file, name, model, cs.sim.flexible_every);
  IntegratorOptions o = cs.sim.options;
  o.parallel.threads = threads;
  double balance0 = NAN;
  const auto t0 = std::chrono::steady_clock::now();
  const RunOutcome r = integrate(
      model, inputs, o,
      [&](const OutputSample& x) {
        group.append(x);
        if (observe) observe(name, model, x);
        progress.update(x.t, x.steps);
        spdlog::debug("{}: output t = {:.6g} s, {} steps, last step {:.3g} s", name, x.t, x.steps, x.last_step);
        for (size_t l = 0; l < s.peaks.size(); ++l) {
          const Eigen::Vector3d u = tip_deflection(model, static_cast<int>(l), x.q);
          LinkPeaks& pk = s.peaks[l];
          pk.u1 = std::max(pk.u1, std::abs(u[0]));
          pk.u2 = std::max(pk.u2, std::abs(u[1]));
          pk.theta = std::max(pk.theta, std::abs(u[2]));
        }
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
  group.attribute("integrator", integrator_name(o.kind));
  if (o.kind == IntegratorKind::Esdirk) group.attribute("method", o.esdirk_table);
  else group.attribute("max_order", static_cast<long>(o.max_order));
  group.attribute("output_dt", o.output_dt);
  group.attribute("threads", static_cast<long>(omp_get_max_threads()));
  group.attribute("steps", static_cast<long>(r.stats.steps));
  group.attribute("residual_evals", static_cast<long>(r.stats.residual_evals));
  group.attribute("factorizations", static_cast<long>(r.stats.factorizations));
  group.attribute("newton_iters", static_cast<long>(r.stats.newton_iters));
  group.attribute("newton_fails", static_cast<long>(r.stats.newton_fails));
  group.attribute("error_test_fails", static_cast<long>(r.stats.error_test_fails));
  std::vector<std::string> kinds;
  for (const auto& in : inputs)
    kinds.push_back(in.prescribed() ? "motion"
                    : (in.torque->stiffness() != 0.0 || in.torque->damping() != 0.0) ? "feedback" : "torque");
  group.attribute("inputs", fmt::format("{}", fmt::join(kinds, ",")));
  group.status(r.status);
  group.close();
  file.end_swmr();  // writes the attributes queued above
  if (!quiet) {
    fmt::print("{:<10} {}: t = {:.3f} s, {} outputs, wall {:.3f} s; steps {}, residuals {}, factorisations {}, "
               "Newton iterations {} (failures {}), error-test failures {}\n",
               name, r.status, r.t_reached, s.samples, s.wall, r.stats.steps, r.stats.residual_evals,
               r.stats.factorizations, r.stats.newton_iters, r.stats.newton_fails, r.stats.error_test_fails);
    for (const LinkPeaks& pk : s.peaks)
      fmt::print("{:<10} {}peak |u1| = {:.6e} m, |u2| = {:.6e} m, |theta| = {:.6e} rad{}", "",
                 s.peaks.size() > 1 ? "link " + pk.name + ": " : "", pk.u1, pk.u2, pk.theta, s.peaks.size() > 1 ? "\n" : "; ");
    fmt::print("{}energy balance drift {:.3e} J (scale {:.3e} J)\n", s.peaks.size() == 1 ? "" : fmt::format("{:<10} ", ""),
               s.energy_drift, s.energy_scale);
  }
  return s;
}

}  // namespace

namespace {
std::vector<double> all_breakpoints(const std::vector<JointInput>& laws) {
  std::vector<double> b;
  for (const auto& l : laws) {
    const auto x = l.breakpoints();
    b.insert(b.end(), x.begin(), x.end());
  }
  return b;
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
    }, all_breakpoints(laws));
  }
  return out;
}

std::atomic<int>& stop_flag() { return g_stop; }

void describe_run(ResultsFile& file, const Case& cs, const Common& c, const std::string& procedure, int n) {
  file.attribute("rfem_version", RFEM_VERSION_STRING);
  file.attribute("build", RFEM_BUILD_DESCRIPTION);
  file.attribute("command_line", c.command_line);
  file.attribute("case_path", cs.path);
  file.attribute("case_text", cs.text);
  file.attribute("case_effective", cs.effective_text);
  std::string ov;
  for (const auto& o : cs.overrides) ov += (ov.empty() ? "" : "\n") + o;
  file.attribute("overrides", ov);
  file.attribute("procedure", procedure);
  if (n >= 0) write_attribute(file.id(), "n", static_cast<long>(n));
  write_attribute(file.id(), "threads", static_cast<long>(omp_get_max_threads()));
}

namespace {
// MemAvailable of /proc/meminfo [B]; infinity where it cannot be read.
double available_memory() {
  std::FILE* f = std::fopen("/proc/meminfo", "r");
  if (!f) return INFINITY;
  char line[256];
  double kb = INFINITY;
  while (std::fgets(line, sizeof line, f))
    if (std::sscanf(line, "MemAvailable: %lf kB", &kb) == 1) break;
  std::fclose(f);
  return kb * 1024.0;
}
}  // namespace

void check_affordable(const Case& cs, const Model& model, const std::vector<JointInput>& inputs, int threads,
                      bool quiet) {
  IntegratorOptions o = cs.sim.options;
  o.parallel.threads = threads;
  const RunEstimate e0 = estimate_run(model, inputs, o, false);
  const double avail = available_memory();
  if (e0.bytes > avail)
    throw CaseError(fmt::format("{}: link.n: a run with n = {} rfes needs about {:.2g} GB of memory, {:.2g} GB are available",
                                cs.path, model.n(), e0.bytes / 1e9, avail / 1e9));
  if (model.n() < kLargeRunRfes || quiet) return;
  const RunEstimate e = estimate_run(model, inputs, o, true);
  fmt::print(stderr,
             "rfem: note: n = {} rfes: about {:.0f} MB of memory; one residual evaluation {:.3g} ms, one Newton "
             "matrix {:.3g} ms, so about {:.2g} s per step (the shipped cases take 400 to 6000 steps at the "
             "default tolerances)\n",
             model.n(), e.bytes / 1e6, e.residual_s * 1e3, e.newton_setup_s * 1e3, e.step_s());
}

void install_signal_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
}

std::vector<RunSummary> simulate_case(const Case& cs, const Model& model, const std::vector<JointInput>& inputs,
                                      ResultsFile& file, const std::string& prefix, bool quiet, const Observer& observe,
                                      int threads) {
  std::vector<RunSummary> runs;
  if (cs.sim.procedure == "paper") {
    for (size_t j = 0; j < inputs.size(); ++j)
      if (!inputs[j].prescribed())
        throw CaseError(cs.inputs[j].where + ": the paper procedure needs a motion law on every joint");
    const Model rigid = rigidify(model);
    runs.push_back(run_one(file, prefix + "rigid", rigid, inputs, cs, quiet, observe, threads));
    if (runs.back().completed) runs.push_back(run_one(file, prefix + "kinematic", model, inputs, cs, quiet, observe, threads));
    if (runs.back().completed)
      runs.push_back(run_one(file, prefix + "force", model, rigid_torque_inputs(rigid, inputs), cs, quiet, observe, threads));
  } else {
    runs.push_back(run_one(file, prefix + "run", model, inputs, cs, quiet, observe, threads));
  }
  file.flush();
  return runs;
}

}  // namespace rfem::app
