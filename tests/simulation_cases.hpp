#pragma once
// The cases and comparisons the simulation tests share (tests/test_simulation.cpp, the stepped
// simulation; tests/test_control_loop.cpp, controllers in the loop).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "../simulation/simulation.hpp"
#include "tests/test_models.hpp"

namespace rfem::test {

// Kane's beam on a torque-driven hub (220 N m against drive damping and friction), 6 rfes.
inline Case hub(double t_end) {
  return read_case(test::source_path("cases/kane_hub_drive.toml"),
                   {"simulation.t_end=" + std::to_string(t_end), "link.n=6", "simulation.output_dt=0.01"});
}

// Kane's aluminium and section (cases/kane_beam.toml).
constexpr const char* kKaneMaterial = R"(
[materials.kane]
E = 7.0e10
G = 2.6923076923e10
rho = 3000.0
[sections.kane]
A = 4.0e-4
Iy = 2.0e-7
Iz = 2.0e-7
J = 4.0e-7
)";

// The same beam on a PD-controlled hub following Kane's spin-up to 2 rad/s in 1 s (no feed-forward).
inline Case pd_hub() {
  return parse_case(std::string(kKaneMaterial) + R"(
[[joints]]
name = "hub"
drive = { inertia = 50.0 }
input = { kind = "pd", reference = { kind = "spinup", Omega = 2.0, T = 1.0 }, kp = 4000.0, kd = 800.0 }
[link]
n = 4
[[link.segments]]
length = 10.0
material = "kane"
section = "kane"
[simulation]
t_end = 1.5
output_dt = 0.01
)",
                    "pd_hub.toml");
}

// pd_hub()'s PD law (kp = 4000, kd = 800 on the spin-up) written as a controller.
inline Controller pd_hub_controller() {
  const auto reference = spinup_law(0.0, 2.0, 1.0);
  return [reference](double t, const Snapshot& y) {
    const MotionSample r = reference->at(t);
    ControlOutput u;
    u.torques["hub"] = 4000.0 * (r.q - y.joint_q[0]) + 800.0 * (r.qd - y.joint_v[0]);
    return u;
  };
}

inline SimulationOptions one_thread() {
  SimulationOptions o;
  o.threads = 1;
  o.keep_series = true;
  return o;
}

inline Table series(const RunResult& r, const std::string& name) { return r.series->table(name); }

inline double max_abs(const Table& t) {
  double m = 0.0;
  for (double x : t.data) m = std::max(m, std::abs(x));
  return m;
}

// max |a − b| over b's rows, each against a's row of the same time (b's rows at times a does not
// have are skipped: a state's own row); at least `matched` rows must be compared.
inline double max_difference(const Table& a, const Table& ta, const Table& b, const Table& tb, long matched = -1) {
  double d = 0.0;
  long i = 0, m = 0;
  for (long j = 0; j < b.rows; ++j) {
    while (i < a.rows && ta.at(i, 0) < tb.at(j, 0) - 1e-12) ++i;
    if (i == a.rows || std::abs(ta.at(i, 0) - tb.at(j, 0)) > 1e-12) continue;
    for (long c = 0; c < a.cols; ++c) d = std::max(d, std::abs(a.at(i, c) - b.at(j, c)));
    ++m;
  }
  EXPECT_GE(m, matched < 0 ? b.rows : matched) << "rows compared";
  return d;
}

}  // namespace rfem::test
