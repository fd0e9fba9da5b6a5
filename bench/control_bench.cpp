// A C++ controller in the loop (rfem::run_controlled), timed: the PD law of the paper's
// deployment (paper_pd_tracking.toml with torque inputs) computed by a C++ callback at a sample
// rate. bench/control_bench.py runs it beside the continuous law, a Python callback and 1 ms chunks.
//
//   rfem_control_bench CASE N SAMPLE_TIME REPEAT      (prints "wall S calls K q1 Q1 …" per repeat)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "../simulation/simulation.hpp"
#include "../solvers/inputs.hpp"

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: %s CASE N SAMPLE_TIME REPEAT\n", argv[0]);
    return 2;
  }
  try {
    // The case's PD joints as torque joints; their laws (the same gains and references) in C++.
    // (A hub inertia on every joint, as bench/control_bench.py sets: without one, psi3 sees only the
    // link's first rfe at high frequency and kd = 60 N m s sampled at 1 kHz is unstable.)
    const rfem::Case cs = rfem::read_case(argv[1], {"joints.*.input={kind=\"torque\", value=0.0}", "joints.*.drive={inertia=0.5}"});
    const int n = std::atoi(argv[2]), repeat = std::atoi(argv[4]);
    const double ts = std::atof(argv[3]);
    const double pi = 3.141592653589793, alpha[3] = {0.5, 0.75, 1.0}, kp = 40.0, kd = 60.0;
    std::shared_ptr<rfem::MotionLaw> ref[3];
    for (int j = 0; j < 3; ++j) ref[j] = rfem::deployment_law(pi, alpha[j], 15.0);
    const char* names[3] = {"psi1", "psi2", "psi3"};
    for (int r = 0; r < repeat; ++r) {
      long calls = 0;
      const rfem::Controller pd = [&](double t, const rfem::Snapshot& y) {
        ++calls;
        rfem::ControlOutput u;
        for (int j = 0; j < 3; ++j) {
          const rfem::MotionSample s = ref[j]->at(t);
          u.torques[names[j]] = kp * (s.q - y.joint_q[j]) + kd * (s.qd - y.joint_v[j]);
        }
        return u;
      };
      rfem::SimulationOptions o;
      o.n = n;
      o.threads = 1;
      rfem::ControlOptions c;
      c.sample_time = ts;
      const auto t0 = std::chrono::steady_clock::now();
      const rfem::RunResult res = rfem::run_controlled(cs, o, pd, c);
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (!res.completed()) {
        std::fprintf(stderr, "rfem_control_bench: %s\n", res.status.to_string().c_str());
        return 1;
      }
      std::printf("wall %.6f calls %ld steps %ld u1 %.9e u2 %.9e theta %.9e\n", wall, calls, res.stats.steps, res.peaks[0].u1,
                  res.peaks[0].u2, res.peaks[0].theta);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rfem_control_bench: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
