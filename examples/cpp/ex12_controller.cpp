// Example 12: your controller in the loop from C++, against the installed library.
//
// Kane's 10 m beam on a motor hub (cases/kane_hub_drive.toml: rotor inertia, damping, friction),
// spun up to Ω = 1 rad/s in 10 s (Kane's spin-up law) by a PD law at 1 kHz, then held at Ω.
// (1) The law as a C++ controller (rfem::run_controlled, zero-order hold) against the case's built-in
//     digital PD at the same sample time: the same bits, so a controller of your own costs what the
//     built-in one does.
// (2) The same law in a loop of your own: an rfem::Simulation advanced 1 ms at a time, the hub read
//     from an encoder and a torque held with set_torque. An IMU glued to the beam's tip reads, once
//     the hub turns steadily, the hub's rate and the centripetal specific force −Ω² L along the
//     beam (less where the beam still vibrates): checked against Ω and Ω² L.
// (3) The state at t = 10 s saved, and a rollout from it that continues the loop: the same bits as
//     the original's continuation.
//
//     ex12_controller CASES_DIR        (CASES_DIR: the repository's cases/; ~4 s)
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "rfem/simulation/simulation.hpp"
#include "rfem/solvers/inputs.hpp"

namespace {

constexpr double kKp = 4.0e4, kKd = 1.2e4, kOmega = 1.0, kT = 10.0, kSample = 1e-3;

// The PD law on Kane's spin-up: the torque at t for the hub at (q, q̇).
double pd(double t, double q, double qd) {
  static const auto reference = rfem::spinup_law(0.0, kOmega, kT);
  const rfem::MotionSample r = reference->at(t);
  return kKp * (r.q - q) + kKd * (r.qd - qd);
}

// The loop of (2) from the simulation's time to `until`: sample, compute, hold, advance one sample.
// Gives the largest |Δ| between the tip IMU's rate and the hub's over the samples after `from`,
// and the mean of the IMU's specific force along the beam there.
void loop(rfem::Simulation& sim, double until, double from, double& rate_gap, double& force_x) {
  rate_gap = 0.0;
  force_x = 0.0;
  int samples = 0;
  for (long k = std::lround(sim.time() / kSample); sim.time() < until - 1e-12; ++k) {
    const rfem::Snapshot y = sim.snapshot();
    const std::vector<double>* encoder = nullptr;
    const std::vector<double>* imu = nullptr;
    for (const auto& [name, values] : y.sensors) {
      if (name == "encoder") encoder = &values;
      if (name == "tip_imu") imu = &values;
    }
    if (y.t > from) {
      rate_gap = std::max(rate_gap, std::abs((*imu)[2] - (*encoder)[1]));
      force_x += (*imu)[3];
      ++samples;
    }
    sim.set_torque("hub", pd(y.t, (*encoder)[0], (*encoder)[1]));
    sim.advance(std::min(until, static_cast<double>(k + 1) * kSample));
    if (sim.status().kind == rfem::RunStatus::Kind::Failed) throw std::runtime_error("the loop's run failed: " + sim.status().to_string());
  }
  if (samples > 0) force_x /= samples;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s CASES_DIR\n", argv[0]);
    return 2;
  }
  const std::string cases = argv[1];
  try {
    const std::vector<std::string> common = {"link.n=8", "simulation.t_end=11.0", "simulation.output_dt=0.01"};
    // 1. The built-in digital PD against the same law written in C++.
    std::vector<std::string> built_in = common;
    built_in.push_back("joints.0.input={kind=\"pd\", reference={kind=\"spinup\", Omega=1.0, T=10.0}, kp=4.0e4, kd=1.2e4, sample_time=1e-3}");
    rfem::SimulationOptions o;
    o.threads = 1;
    o.keep_series = true;
    const rfem::Case hub = rfem::read_case(cases + "/kane_hub_drive.toml", common);
    rfem::Simulation digital(rfem::read_case(cases + "/kane_hub_drive.toml", built_in), o);
    digital.advance(digital.t_end());
    const rfem::RunResult a = digital.finish();
    const rfem::RunResult b = rfem::run_controlled(hub, o, [](double t, const rfem::Snapshot& y) {
      rfem::ControlOutput u;
      u.torques["hub"] = pd(t, y.joint_q[0], y.joint_v[0]);
      return u;
    }, {kSample, 0});
    const rfem::Table qa = a.series->table("joint_q"), qb = b.series->table("joint_q");
    double diff = 0.0;
    for (size_t i = 0; i < qa.data.size(); ++i) diff = std::max(diff, std::abs(qa.data[i] - qb.data[i]));
    std::printf("built-in digital PD: %s, hub at t = 11 s %.9f rad, peak tip u1 %.6e m\n", a.status.to_string().c_str(),
                qa.data.back(), a.peaks[0].u1);
    std::printf("C++ controller:      %s, hub at t = 11 s %.9f rad, peak tip u1 %.6e m\n", b.status.to_string().c_str(),
                qb.data.back(), b.peaks[0].u1);
    std::printf("largest difference in the hub angle: %.1e rad (%zu samples)\n", diff, qa.data.size());

    // 2. A loop of your own, with an encoder on the hub and an IMU at the beam's tip.
    std::ifstream in(cases + "/kane_hub_drive.toml");
    std::stringstream text;
    text << in.rdbuf() << R"(
[[sensors]]
name = "encoder"
kind = "encoder"
joint = "hub"
[[sensors]]
name = "tip_imu"
kind = "imu"
)";
    const rfem::Case with_sensors = rfem::with_overrides(rfem::parse_case(text.str(), cases + "/kane_hub_drive.toml"), common);
    rfem::Simulation stepped(with_sensors, o);
    double gap = 0.0, fx = 0.0;
    loop(stepped, 10.0, 10.0, gap, fx);  // to t = 10 s; the state saved there; on to 11 s
    const rfem::SimulationState at10 = stepped.state();
    loop(stepped, 11.0, 10.5, gap, fx);
    const rfem::RunResult c = stepped.finish();
    const double L = 10.0;
    std::printf("loop of 1 ms steps: %s, hub at t = 11 s %.9f rad, the same as (1): %s\n", c.status.to_string().c_str(),
                c.series->table("joint_q").data.back(), c.series->table("joint_q").data.back() == qb.data.back() ? "yes" : "no");
    std::printf("tip IMU over the last 0.5 s: rate within %.3e rad/s of the hub's; specific force along the beam %.6f m/s^2"
                " (centripetal -Omega^2 L = %.6f)\n", gap, fx, -kOmega * kOmega * L);

    // 3. A rollout from the state at t = 10 s: the same loop, the same bits.
    rfem::SimulationOptions from = o;
    from.state = std::make_shared<const rfem::SimulationState>(at10);
    rfem::Simulation rollout(with_sensors, from);
    double gap2 = 0.0, fx2 = 0.0;
    loop(rollout, 11.0, 10.5, gap2, fx2);
    const rfem::RunResult d = rollout.finish();
    std::printf("rollout from the state at t = 10 s: hub at t = 11 s %.9f rad, the same bits as the loop's: %s\n",
                d.series->table("joint_q").data.back(),
                d.series->table("joint_q").data.back() == c.series->table("joint_q").data.back() && gap2 == gap && fx2 == fx ? "yes" : "no");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ex12_controller: %s\n", e.what());
    return 1;
  }
  return 0;
}
