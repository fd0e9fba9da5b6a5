// A simulation a caller steps (simulation/simulation.hpp): one advance to the end is `rfem run` bit for
// bit; chunks agree with one run to the integrator's accuracy; a simulation started from a saved
// state continues the original bit for bit; a held torque equal to the case's law changes nothing;
// the energy books balance with a held torque; bad arguments are refused with one line; IDA steps
// too; a procedure's run is the integrator's. Controllers in the loop: tests/test_control_loop.cpp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "../core/positions.hpp"
#include "../results/reader.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/sensors.hpp"
#include "../simulation/simulation.hpp"
#include "../studies/runs.hpp"
#include "../studies/show.hpp"
#include "tests/simulation_cases.hpp"
#include "tests/test_models.hpp"

using namespace rfem;
using namespace rfem::test;

TEST(Simulation, OneAdvanceToTheEndIsTheRunBitForBit) {
  const Case cs = hub(0.5);
  RunRequest rq;
  rq.threads = 1;
  const RunResult run = run_case(cs, rq).at(0);
  Simulation sim(cs, one_thread());
  EXPECT_EQ(sim.advance(sim.t_end()).kind, RunStatus::Kind::Completed);
  const RunResult r = sim.finish();
  ASSERT_TRUE(r.completed()) << r.status;
  EXPECT_EQ(r.samples, run.samples);
  EXPECT_EQ(r.stats.steps, run.stats.steps);
  for (const char* name : {"tip_deflection", "joint_q", "joint_tau", "energy"})
    EXPECT_EQ(series(r, name).data, series(run, name).data) << name;
}

TEST(Simulation, ChunksAgreeWithOneRunToTheIntegratorsAccuracy) {
  // 1 ms chunks end a step at every millisecond: another step sequence, the same solution within
  // the default tolerances' accuracy (README "Performance": integration error below 1e-4 of the
  // peaks; two such solutions differ by at most twice that).
  const Case cs = hub(0.5);
  Simulation whole(cs, one_thread()), chunks(cs, one_thread());
  whole.advance(0.5);
  for (int k = 1; k <= 500; ++k) ASSERT_EQ(chunks.advance(std::min(0.5, k * 1e-3)).kind, k < 500 ? RunStatus::Kind::Running : RunStatus::Kind::Completed);
  EXPECT_EQ(chunks.time(), 0.5);
  const RunResult a = whole.finish(), b = chunks.finish();
  const Table ua = series(a, "tip_deflection"), ub = series(b, "tip_deflection");
  const double d = max_difference(ua, series(a, "time"), ub, series(b, "time"));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", d / max_abs(ua));
  RecordProperty("chunks_difference_relative", buf);
  EXPECT_LT(d, 2e-4 * max_abs(ua));
  EXPECT_GT(b.stats.steps, 500);  // a step ended at every chunk
}

TEST(Simulation, StartedFromAStateContinuesTheOriginalBitForBit) {
  const Case cs = hub(0.4);
  Simulation first(cs, one_thread());
  first.advance(0.173);  // between outputs
  const auto state = std::make_shared<const SimulationState>(first.state());
  const std::string path = (std::filesystem::temp_directory_path() / "rfem_test_state.h5").string();
  save_state(*state, path);
  first.advance(0.4);
  SimulationOptions o = one_thread();
  o.state = std::make_shared<const SimulationState>(load_state(path));
  std::filesystem::remove(path);
  Simulation second(cs, o);
  EXPECT_EQ(second.time(), 0.173);
  EXPECT_EQ(second.q(), [&] {
    Simulation again(cs, one_thread());
    again.advance(0.173);
    return again.q();
  }());
  second.advance(0.4);
  EXPECT_EQ(first.q(), second.q());
  EXPECT_EQ(first.v(), second.v());
  const RunResult a = first.finish(), b = second.finish();
  const Table tb = series(b, "time");
  EXPECT_EQ(tb.at(0, 0), 0.173);  // the state's own row, then the grid
  EXPECT_NEAR(tb.at(1, 0), 0.18, 1e-15);
  EXPECT_EQ(max_difference(series(a, "tip_deflection"), series(a, "time"), series(b, "tip_deflection"), tb, tb.rows - 1), 0.0);
}

TEST(Simulation, AStateCarriesADigitalLawsHeldAndDelayedValues) {
  // A digital PD with a delay of two samples remembers three outputs at any time: a state saved
  // at a sample (0.2 s) and between samples (0.301 s) carries them (through its file), and the
  // simulation started from it continues the original bit for bit. Without that memory the held
  // torque would restart from zero for two samples and the runs part.
  const Case cs = with_overrides(pd_hub(), {"joints.0.input.sample_time=2e-3", "joints.0.input.delay=2", "simulation.t_end=0.5"});
  for (double t_save : {0.2, 0.301}) {
    Simulation first(cs, one_thread());
    first.advance(t_save);
    const SimulationState saved = first.state();
    EXPECT_EQ(saved.laws.size(), 5u);  // the hub's count; last sample's time, held, two delayed
    const std::string path = (std::filesystem::temp_directory_path() / "rfem_test_digital_state.h5").string();
    save_state(saved, path);
    first.advance(0.5);
    SimulationOptions o = one_thread();
    o.state = std::make_shared<const SimulationState>(load_state(path));
    std::filesystem::remove(path);
    Simulation second(cs, o);
    second.advance(0.5);
    EXPECT_EQ(first.q(), second.q()) << "saved at " << t_save;
    EXPECT_EQ(first.v(), second.v()) << "saved at " << t_save;
  }
}

TEST(Simulation, AHeldTorqueEqualToTheCaseLawChangesNothing) {
  const Case cs = hub(0.3);
  Simulation a(cs, one_thread()), b(cs, one_thread()), c(cs, one_thread());
  a.advance(0.1);
  a.advance(0.3);
  b.set_torque("hub", 220.0);  // the case's own value, held from t = 0: the same bits
  b.advance(0.1);
  b.advance(0.3);
  EXPECT_EQ(a.q(), b.q());
  // Held again at 0.1 s: the accelerations there are solved afresh instead of taken from the last
  // stage (equal to the Newton tolerance), so equal to the integrator's accuracy (1e-4 of the peak).
  c.advance(0.1);
  c.set_torque("hub", 220.0);
  c.advance(0.3);
  const VecX qa = a.q();
  EXPECT_LT((qa - c.q()).cwiseAbs().maxCoeff(), 1e-4 * qa.cwiseAbs().maxCoeff());
  // A different torque does change the motion, and by the right sign.
  Simulation d(cs, one_thread());
  d.set_torque("hub", 440.0);
  d.advance(0.3);
  const int hub_q = d.model().joint_index(0);
  EXPECT_GT(d.q()[hub_q], qa[hub_q]);
}

TEST(Simulation, BadArgumentsAreRefusedWithOneLine) {
  const Case cs = hub(0.2);
  Simulation sim(cs, one_thread());
  EXPECT_THROW(sim.set_torque("elbow", 1.0), std::invalid_argument);
  EXPECT_THROW(sim.set_torque("hub", NAN), std::invalid_argument);
  EXPECT_THROW(sim.set_reference("hub", 1.0), std::invalid_argument);  // a torque joint has no PD gains
  EXPECT_THROW(sim.advance(0.3), std::invalid_argument);               // beyond t_end
  sim.advance(0.1);
  EXPECT_THROW(sim.advance(0.05), std::invalid_argument);  // backwards
  EXPECT_THROW(sim.advance(NAN), std::invalid_argument);
  // Another model's state (other n).
  SimulationOptions o = one_thread();
  o.state = std::make_shared<const SimulationState>(sim.state());
  EXPECT_THROW(Simulation(read_case(test::source_path("cases/kane_hub_drive.toml"), {"link.n=7", "simulation.t_end=0.2"}), o),
               std::invalid_argument);
  // Controllers: bad sample times; one that throws or names an unknown joint fails the run with
  // its message, the rows before kept in the file.
  ControlOptions c;
  const Controller zero = [](double, const Snapshot&) { return ControlOutput{}; };
  c.sample_time = 0.0;
  EXPECT_THROW(run_controlled(cs, one_thread(), zero, c), std::invalid_argument);
  c.sample_time = 1.0;
  EXPECT_THROW(run_controlled(cs, one_thread(), zero, c), std::invalid_argument);
  c.sample_time = 0.01;
  const std::string path = (std::filesystem::temp_directory_path() / "rfem_test_controller.h5").string();
  SimulationOptions f = one_thread();
  f.output = path;
  const RunResult r = run_controlled(cs, f, [](double t, const Snapshot&) {
    if (t > 0.1) throw std::runtime_error("sensor lost");
    return ControlOutput{};
  }, c);
  EXPECT_EQ(r.status.kind, RunStatus::Kind::Failed);
  EXPECT_NE(r.status.reason.find("controller: sensor lost"), std::string::npos) << r.status;
  {
    const ResultsReader in(path);
    EXPECT_EQ(in.attribute("run", "status").rfind("failed: controller: sensor lost", 0), 0u);
    EXPECT_GE(in.table("run/time").rows, 11);  // t = 0 … 0.1 s
    EXPECT_GE(in.table("run/control").rows, 11);
  }
  const RunResult u = run_controlled(cs, f, [](double, const Snapshot&) {
    ControlOutput out;
    out.torques["elbow"] = 1.0;
    return out;
  }, c);
  EXPECT_NE(u.status.reason.find("no joint named 'elbow'"), std::string::npos) << u.status;
  std::filesystem::remove(path);
}

TEST(Simulation, StrainGaugesReadTheBeamsBendingMomentAndSensorsAreReproducible) {
  // A 2 m cantilever held horizontally under gravity, in static equilibrium at t = 0: the bending
  // moment at an sde at x is the weight beyond it times its lever arm, M = ρ A g (L − x)² / 2 (the
  // rfes' masses lie beyond the sde exactly as the beam's), so a gauge at c above the axis reads
  // ε = M c / (E Iy) (tension on top). The deflection is 4e-4 of L: the geometry's change of the
  // lever arms is far below the 1e-4 asserted.
  const Case cs = parse_case(std::string(kKaneMaterial) + R"(
[[joints]]
name = "hub"
input = { kind = "constant_rate", rate = 0.0 }
[link]
n = 20
[[link.segments]]
length = 2.0
material = "kane"
section = "kane"
[gravity]
g = 9.81
[[sensors]]
name = "gauge"
kind = "strain"
at = 0.5
face = "z"
distance = 0.01
[[sensors]]
name = "side"
kind = "strain"
at = 0.5
face = "y"
distance = 0.01
[[sensors]]
name = "noisy"
kind = "strain"
at = 0.5
distance = 0.01
noise = 1e-7
quantum = 1e-8
seed = 7
[[sensors]]
name = "enc"
kind = "encoder"
joint = "hub"
[[sensors]]
name = "tip"
kind = "tip"
[[sensors]]
name = "imu"
kind = "imu"
[[sensors]]
name = "tip_v"
kind = "tip"
quantity = "velocity"
[[sensors]]
name = "tip_a"
kind = "tip"
quantity = "acceleration"
frame = "link"
[simulation]
t_end = 0.02
output_dt = 0.01
)", "cantilever.toml");
  const Model model = build_model(cs);
  double x = NAN;  // the sde nearest 0.5 m
  for (const Sde& e : model.links[0].d.sdes)
    if (std::isnan(x) || std::abs(e.position - 0.5) < std::abs(x - 0.5)) x = e.position;
  const double M = 3000.0 * 4.0e-4 * 9.81 * (2.0 - x) * (2.0 - x) / 2.0;
  const double exact = M * 0.01 / (7.0e10 * 2.0e-7);
  Simulation sim(cs, one_thread());
  const Snapshot y = sim.snapshot();
  ASSERT_EQ(y.sensors.size(), 8u);
  EXPECT_EQ(y.sensors[0].first, "gauge");
  EXPECT_NEAR(y.sensors[0].second.at(0), exact, 1e-4 * exact);
  EXPECT_LT(std::abs(y.sensors[1].second.at(0)), 1e-6 * exact);  // no bending about z
  EXPECT_EQ(y.sensors[3].second.size(), 2u);                     // encoder: q, q̇
  EXPECT_NEAR(y.sensors[4].second.at(1), y.tip_deflection[0][1], 1e-15);
  // An IMU on the tip at rest reads no rate and the specific force +g upwards in the axes of the
  // tip rfe, turned by its slope φ2 about y: (−g sin φ2, 0, g cos φ2), to the equilibrium's residual
  // acceleration (the static solution's 1e-10 relative tolerance); the tip neither moves nor accelerates.
  const VecX q = sim.q();
  const double slope = q[model.rfe_index(0, model.links[0].n() - 1) + 4];
  EXPECT_GT(slope, 1e-5);  // (bent down: x turns towards −z, a positive rotation about y)
  const std::vector<double>& imu = y.sensors[5].second;
  ASSERT_EQ(imu.size(), 6u);
  for (int k = 0; k < 3; ++k) EXPECT_EQ(imu[static_cast<size_t>(k)], 0.0);
  EXPECT_NEAR(imu[3], -9.81 * std::sin(slope), 1e-8);
  EXPECT_NEAR(imu[4], 0.0, 1e-8);
  EXPECT_NEAR(imu[5], 9.81 * std::cos(slope), 1e-8);
  for (int s = 6; s < 8; ++s)
    for (double x : y.sensors[static_cast<size_t>(s)].second) EXPECT_NEAR(x, 0.0, 1e-8);
  // Noise and resolution: multiples of the quantum, within 6σ of the exact value, the same again
  // from the same seed.
  const double noisy = y.sensors[2].second.at(0);
  EXPECT_NEAR(noisy / 1e-8, std::round(noisy / 1e-8), 1e-6);
  EXPECT_NEAR(noisy, exact, 6e-7 + 1e-8);
  EXPECT_NE(noisy, y.sensors[0].second.at(0));
  Simulation again(cs, one_thread());
  EXPECT_EQ(again.snapshot().sensors[2].second, y.sensors[2].second);
  // Recorded at every output (time first), the gauge's column as in the snapshot at t = 0.
  sim.advance(sim.t_end());
  const RunResult r = sim.finish();
  ASSERT_EQ(r.sensors.rows, 3);
  EXPECT_EQ(r.sensor_columns.at(4), "enc/q");
  EXPECT_NEAR(r.sensors.at(0, 1), exact, 1e-4 * exact);
}

TEST(Simulation, ACaseStartsFromASavedStateAsTheProgramRunsIt) {
  // [simulation] state = "FILE": rfem run (run_case, run_into_file) goes on from the saved state,
  // the same bits as the simulation it was saved from; another model's state is refused by key.
  const Case cs = hub(0.3);
  Simulation first(cs, one_thread());
  first.advance(0.12);
  const std::string path = (std::filesystem::temp_directory_path() / "rfem_test_case_state.h5").string();
  save_state(first.state(), path);
  first.advance(0.3);
  RunRequest rq;
  rq.threads = 1;
  const Case from = with_overrides(cs, {"simulation.state=\"" + path + "\""});
  const RunResult r = run_case(from, rq).at(0);
  ASSERT_TRUE(r.completed()) << r.status;
  const Table q = series(r, "joint_q");
  EXPECT_EQ(series(r, "time").at(0, 0), 0.12);
  EXPECT_EQ(q.at(q.rows - 1, 0), first.q()[first.model().joint_index(0)]);
  try {
    run_case(with_overrides(from, {"link.n=7"}), rq);
    ADD_FAILURE() << "another model's state was accepted";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("simulation.state"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("another model"), std::string::npos) << e.what();
  }
  EXPECT_THROW(run_case(with_overrides(cs, {"simulation.state=\"/no/such/state.h5\""}), rq), CaseError);
  std::filesystem::remove(path);
}

TEST(Simulation, TheEnergyBooksBalanceWithATorqueHeldOnAPdJoint) {
  // Held values switched mid-run (a torque, then a reference) are inputs like any other: the
  // balance T + V + dissipated − input work stays within the integrator's tolerance of its start
  // (measured 9e-8 of the scale; the input work of a held torque is integrated exactly per step).
  const Case cs = pd_hub();
  Simulation sim(cs, one_thread());
  sim.advance(0.3);
  sim.set_torque("hub", 5000.0);
  sim.advance(0.6);
  sim.set_reference("hub", 0.5, 0.0, 0.0);
  sim.advance(sim.t_end());
  const RunResult r = sim.finish();
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3e", r.energy_drift / r.energy_scale);
  RecordProperty("energy_drift_relative", buf);
  EXPECT_LT(r.energy_drift, 1e-6 * r.energy_scale);
}

// The noise of the recorded sensors is part of a state, so a
// simulation started from it records what the original run recorded, bit for bit, whether the state
// was taken on the output grid or between two outputs (whose own row then draws no shared noise).
TEST(Simulation, NoisySensorsGoOnBitForBitFromAStateOnAndOffTheGrid) {
  std::string text;
  {
    std::ifstream in(test::source_path("cases/kane_hub_drive.toml"));
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  text += "\n[[sensors]]\nname = \"enc\"\nkind = \"encoder\"\njoint = \"hub\"\nnoise = 1e-3\n";
  const Case cs = parse_case(text, test::source_path("cases/kane_hub_drive.toml"),
                             {"simulation.t_end=0.4", "link.n=6", "simulation.output_dt=0.01"});
  for (const double at : {0.2, 0.173}) {
    Simulation a(cs, one_thread());
    a.advance(at);
    SimulationOptions o = one_thread();
    o.state = std::make_shared<const SimulationState>(a.state());
    a.advance(0.4);
    const RunResult ra = a.finish();
    Simulation b(cs, o);
    b.advance(0.4);
    const RunResult rb = b.finish();
    ASSERT_EQ(ra.sensors.cols, 3);  // time, enc/q, enc/qd
    ASSERT_GT(rb.sensors.rows, 10);
    // Row by row from the end: the same time, the same noisy readings.
    for (long k = 1; k <= rb.sensors.rows - (at == 0.2 ? 0 : 1); ++k)
      for (long c = 0; c < 3; ++c)
        ASSERT_EQ(ra.sensors.at(ra.sensors.rows - k, c), rb.sensors.at(rb.sensors.rows - k, c)) << "state at " << at << ", row −" << k;
    // (and the noise is there: the reading is not the exact joint angle)
    EXPECT_NE(ra.sensors.at(ra.sensors.rows - 1, 1), series(ra, "joint_q").at(ra.sensors.rows - 1, 0));
  }
}

// IDA's BDF behind the same engine: stepped in 10 ms chunks (each one IDA's stop time) and started
// again from a state taken mid-run (IDA restarts there), it agrees with one BDF run to the
// integrator's accuracy (README "Performance": integration error below 1e-4 of the peaks; two such
// solutions differ by at most twice that).
TEST(Simulation, BdfIsSteppedAndStartsFromAStateWithinItsAccuracy) {
  Case cs = hub(0.5);
  cs.sim.options.kind = IntegratorKind::Bdf;
  Simulation whole(cs, one_thread()), chunks(cs, one_thread());
  ASSERT_EQ(whole.advance(0.5).kind, RunStatus::Kind::Completed);
  for (int k = 1; k <= 50; ++k) {
    if (k == 20) chunks.set_torque("hub", 220.0);  // (the case's own torque, held: IDA restarts from it)
    ASSERT_EQ(chunks.advance(std::min(0.5, k * 1e-2)).kind, k < 50 ? RunStatus::Kind::Running : RunStatus::Kind::Completed);
  }
  Simulation first(cs, one_thread());
  first.advance(0.25);
  SimulationOptions o = one_thread();
  o.state = std::make_shared<const SimulationState>(first.state());
  Simulation second(cs, o);
  ASSERT_EQ(second.advance(0.5).kind, RunStatus::Kind::Completed);
  const RunResult a = whole.finish(), b = chunks.finish(), c = second.finish();
  ASSERT_TRUE(a.completed() && b.completed() && c.completed()) << a.status << b.status << c.status;
  const Table ua = series(a, "tip_deflection");
  EXPECT_LT(max_difference(ua, series(a, "time"), series(b, "tip_deflection"), series(b, "time")), 2e-4 * max_abs(ua));
  EXPECT_LT(max_difference(ua, series(a, "time"), series(c, "tip_deflection"), series(c, "time")), 2e-4 * max_abs(ua));
  EXPECT_EQ(series(c, "time").data.front(), 0.25);
}

// A procedure's run is a Simulation advanced to t_end: the same bits as the integrator called
// directly on the same model and inputs (one engine, not two).
TEST(Simulation, AProcedureRunIsTheIntegratorsRunBitForBit) {
  const Case cs = hub(0.3);
  RunRequest rq;
  rq.threads = 1;
  const RunResult run = run_case(cs, rq).at(0);
  IntegratorOptions o = cs.sim.options;
  o.parallel.threads = 1;
  std::vector<double> tips;
  const RunOutcome direct = integrate(run.model, joint_inputs(cs), o, [&](const OutputSample& x) {
    const Vec3 u = tip_deflection(*run.model, 0, x.q);
    tips.insert(tips.end(), {u[0], u[1], u[2]});
  });
  ASSERT_TRUE(direct.completed() && run.completed());
  EXPECT_EQ(direct.stats.steps, run.stats.steps);
  EXPECT_EQ(tips, series(run, "tip_deflection").data);
}

// `rfem show` counts a reduced link's unknowns as the run has them: its reduction's (axial rows,
// modes and the modal derivatives the reduction keeps), not a formula of its own (which said 47
// for Kane's beam with 4 modes and 2 derivatives; the equations have 45).
TEST(Simulation, ShowCountsTheUnknownsTheRunHas) {
  for (const char* derivatives : {"link.derivatives=0", "link.derivatives=2"}) {
    const Case cs = read_case(test::source_path("cases/kane_spinup.toml"), {"link.modes=4", derivatives});
    Simulation sim(cs, one_thread());
    EXPECT_EQ(show_model(cs).unknowns, sim.equations().unknowns()) << derivatives;
  }
}

TEST(Simulation, AStructureWithoutJointsRunsClampedToTheGround) {
  // Kane's beam with no joints (it was refused: "a run needs at least one base joint"), under a
  // weak gravity (g = 0.0981: tip sag 1e-3 of L, geometric nonlinearity ~1e-6). Started at its
  // static equilibrium it stays there (a fixed point of the equations: every sample's tip within
  // 1e-9 of the first, the integrator's atol scale); the sag at n = 10, 20, 40 converges with order
  // 2 (±0.1, as the tip-load sag in test_cantilever) to the Timoshenko cantilever under its weight,
  // qL⁴/8EI + qL²/2κGA (Richardson within 1e-4: the (w/L)² nonlinearity and the order's spread). Started undeformed it swings about that
  // equilibrium with its energy conserved (balance within 1e-6 of the energy's scale: the drift
  // of the integrator's error, no sde damping).
  auto beam = [](int n, const char* initial) {
    return parse_case(std::string(kKaneMaterial) + R"(
[link]
n = )" + std::to_string(n) + R"(
[[link.segments]]
length = 10.0
material = "kane"
section = "kane"
[gravity]
g = 0.0981
[simulation]
t_end = 2.0
output_dt = 0.05
initial = ")" + initial + "\"\n");
  };
  double sag[3];
  for (int i : {0, 1, 2}) {
    Simulation sim(beam(10 << i, "static"), one_thread());
    ASSERT_EQ(sim.advance(sim.t_end()).kind, RunStatus::Kind::Completed);
    const RunResult r = sim.finish();
    const Table u = series(r, "tip_deflection");
    sag[i] = u.at(0, 1);
    for (long k = 0; k < u.rows; ++k) EXPECT_NEAR(u.at(k, 1), sag[i], 1e-9) << "sample " << k;
  }
  const Case c = beam(20, "static");
  const Segment& s = c.links[0].link.segments[0];
  const double q = s.material.rho * s.section.A * 0.0981, L = s.length;
  const double exact = -(q * std::pow(L, 4) / (8 * s.material.E * s.section.Iy) +
                         q * L * L / (2 * s.section.kappa_z * s.material.G * s.section.A));
  EXPECT_NEAR(std::log2((sag[1] - sag[0]) / (sag[2] - sag[1])), 2.0, 0.1);
  EXPECT_NEAR(sag[2] + (sag[2] - sag[1]) / 3.0, exact, 1e-4 * std::abs(exact));
  Simulation swing(beam(20, "undeformed"), one_thread());
  ASSERT_EQ(swing.advance(swing.t_end()).kind, RunStatus::Kind::Completed);
  const RunResult r = swing.finish();
  const Table e = series(r, "energy"), u = series(r, "tip_deflection");
  double scale = 0.0, drift = 0.0;
  for (long k = 0; k < e.rows; ++k) {
    scale = std::max({scale, std::abs(e.at(k, 0)), std::abs(e.at(k, 1)), std::abs(e.at(k, 2))});
    drift = std::max(drift, std::abs(e.at(k, 5)));
  }
  EXPECT_GT(max_abs(u), 1.5 * std::abs(exact));  // it swings past the equilibrium
  EXPECT_LT(drift, 1e-6 * scale);
}
