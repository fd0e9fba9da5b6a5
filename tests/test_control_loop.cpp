// Controllers in the loop (studies/control_loop.cpp, Simulation::sample_every): a digital PD
// converges to the continuous law at first order in its sample time and is the same law as a
// controller bit for bit (one sample-and-hold); a controller starts from a state's time; a loop that
// feeds energy in ends diverged; a controller's failure is typed; BDF is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "../simulation/simulation.hpp"
#include "../studies/runs.hpp"
#include "tests/simulation_cases.hpp"
#include "tests/test_models.hpp"

using namespace rfem;
using namespace rfem::test;

TEST(Simulation, DigitalPdConvergesToTheContinuousLawAtFirstOrder) {
  // A controller computing the case's PD law from the sampled joint, held for a sample: the error
  // against the continuous law is the zero-order hold's, O(Ts).
  const Case cs = pd_hub();
  RunRequest rq;
  rq.threads = 1;
  const RunResult continuous = run_case(cs, rq).at(0);
  const Controller pd = pd_hub_controller();
  std::vector<double> errors;
  for (double ts : {4e-3, 2e-3, 1e-3}) {
    ControlOptions c;
    c.sample_time = ts;
    const RunResult r = run_controlled(cs, one_thread(), pd, c);
    ASSERT_TRUE(r.completed()) << r.status;
    const Table a = series(continuous, "joint_q"), b = series(r, "joint_q");
    errors.push_back(max_difference(a, series(continuous, "time"), b, series(r, "time")));
    // The books balance with the controller in the loop: the input work of the held torques is
    // integrated exactly over steps that end at the samples.
    EXPECT_LT(r.energy_drift, 1e-6 * r.energy_scale) << "Ts = " << ts;
  }
  for (size_t i = 1; i < errors.size(); ++i) {
    const double order = std::log2(errors[i - 1] / errors[i]);
    RecordProperty("order_" + std::to_string(i), std::to_string(order));
    EXPECT_NEAR(order, 1.0, 0.15) << "errors " << errors[i - 1] << " -> " << errors[i];
  }
}

TEST(Simulation, TheBuiltInDigitalPdIsTheSameLawAsAControllerBitForBit) {
  // `pd` with sample_time: the case's law sampled and held by the integrator itself; the same law
  // written as a controller at the same rate takes the same steps on the same values; a stepped
  // simulation of the case samples it too (chunks end steps elsewhere: to the tolerances).
  const Case continuous = pd_hub();
  const Case digital = with_overrides(continuous, {"joints.0.input.sample_time=2e-3"});
  RunRequest rq;
  rq.threads = 1;
  const RunResult builtin = run_case(digital, rq).at(0);
  ASSERT_TRUE(builtin.completed()) << builtin.status;
  const Controller pd = pd_hub_controller();
  ControlOptions c;
  c.sample_time = 2e-3;
  const RunResult loop = run_controlled(with_overrides(continuous, {"joints.0.input={kind=\"torque\", value=0.0}", "joints.0.drive={inertia=50.0}"}),
                                        one_thread(), pd, c);
  ASSERT_TRUE(loop.completed()) << loop.status;
  EXPECT_EQ(builtin.stats.steps, loop.stats.steps);
  EXPECT_EQ(series(builtin, "joint_q").data, series(loop, "joint_q").data);
  EXPECT_EQ(series(builtin, "tip_deflection").data, series(loop, "tip_deflection").data);
  // A simulation of the digital case, stepped in chunks that are not samples, samples the same.
  Simulation sim(digital, one_thread());
  for (double t = 0.37; t < sim.t_end(); t += 0.37) sim.advance(t);
  sim.advance(sim.t_end());
  const RunResult stepped = sim.finish();
  // (to the integrator's relative tolerance; a law that did not sample leaves the hub at rest)
  const double q_end = series(builtin, "joint_q").data.back();
  EXPECT_NEAR(series(stepped, "joint_q").data.back(), q_end, 1e-6 * std::abs(q_end));
  // A delay of one sample is another law (later by Ts), and a sample time with BDF is refused.
  const RunResult late = run_case(with_overrides(digital, {"joints.0.input.delay=1"}), rq).at(0);
  EXPECT_NE(series(late, "joint_q").data, series(builtin, "joint_q").data);
  EXPECT_THROW(run_case(with_overrides(digital, {"simulation.integrator=\"bdf\""}), rq), CaseError);
}

// A closed loop that feeds energy in (positive feedback on the hub's rate) ends as diverged within
// its first simulated second, not "completed" after hundreds of thousands of steps.
TEST(Simulation, ADivergingLoopEndsDivergedWithItsRowsKept) {
  const Case cs = hub(1.0);
  const RunResult r = run_controlled(cs, one_thread(), [](double, const Snapshot& y) {
    ControlOutput u;
    u.torques["hub"] = 1e5 * y.joint_v[0] + 1e3;
    return u;
  }, ControlOptions{0.01, 0, {}});
  ASSERT_EQ(r.status.kind, RunStatus::Kind::Failed) << r.status;
  EXPECT_EQ(r.status.reason.rfind("diverged at t = ", 0), 0u) << r.status;
  EXPECT_LT(r.t_reached, 1.0);
  EXPECT_LT(r.stats.steps, 50000);
  EXPECT_GT(r.samples, 1);
  EXPECT_EQ(series(r, "time").rows, r.samples);
}

// A controller started from a state later than its first sample time samples from the state's time on.
TEST(Simulation, AControllerStartsFromAStatesTime) {
  const Case cs = hub(0.3);
  Simulation s(cs, one_thread());
  s.advance(0.105);
  SimulationOptions o = one_thread();
  o.state = std::make_shared<const SimulationState>(s.state());
  std::vector<double> called;
  const RunResult r = run_controlled(cs, o, [&](double t, const Snapshot& y) {
    EXPECT_EQ(t, y.t);
    called.push_back(t);
    ControlOutput u;
    u.torques["hub"] = 200.0;
    return u;
  }, ControlOptions{0.01, 0, {}});
  ASSERT_TRUE(r.completed()) << r.status;
  ASSERT_FALSE(called.empty());
  EXPECT_NEAR(called.front(), 0.11, 1e-12);  // the first sample after the state's time
  EXPECT_NEAR(called.back(), 0.29, 1e-12);
  // Bad sample times and delays are refused before the run.
  EXPECT_THROW(run_controlled(cs, one_thread(), [](double, const Snapshot&) { return ControlOutput{}; }, ControlOptions{1e-300, 0, {}}),
               std::invalid_argument);
  EXPECT_THROW(run_controlled(cs, one_thread(), [](double, const Snapshot&) { return ControlOutput{}; }, ControlOptions{0.01, 1000000, {}}),
               std::invalid_argument);
}

// A controller's failure reaches its caller typed (ControllerError), not as text to match: a value
// that is not finite is refused by the loop (NotFinite), an exception is the controller's (Threw);
// either way the run ends failed with the same words at that sample.
TEST(Simulation, AControllersFailureIsTyped) {
  const Case cs = hub(0.2);
  for (const bool throws : {false, true}) {
    std::vector<ControllerError> seen;
    ControlOptions c{0.01, 0, {}};
    c.on_error = [&](const ControllerError& e) { seen.push_back(e); };
    const RunResult r = run_controlled(cs, one_thread(), [throws](double t, const Snapshot&) {
      ControlOutput u;
      if (t > 0.045 && throws) throw std::runtime_error("sensor lost");
      u.torques["hub"] = t > 0.045 ? NAN : 220.0;
      return u;
    }, c);
    ASSERT_EQ(seen.size(), 1u);
    EXPECT_EQ(seen[0].kind(), throws ? ControllerError::Kind::Threw : ControllerError::Kind::NotFinite);
    EXPECT_DOUBLE_EQ(seen[0].t(), 0.05);
    ASSERT_EQ(r.status.kind, RunStatus::Kind::Failed);
    EXPECT_EQ(r.status.reason, seen[0].what());
    EXPECT_DOUBLE_EQ(r.t_reached, 0.05);  // (every row up to that sample kept)
  }
}

// A controller in the loop is the stepper's sample-and-hold, as a digital law is: f runs at every
// k·period with the simulation standing exactly there; BDF's steps do not stop at samples, so it is
// refused in one line naming the key.
TEST(Simulation, AControllerIsTheSteppersSampleAndHold) {
  const Case cs = hub(0.1);
  Simulation sim(cs, one_thread());
  std::vector<double> at;
  sim.sample_every(0.025, 1, [&](double t) {
    EXPECT_EQ(sim.time(), t);
    at.push_back(t);
    sim.set_torque("hub", 220.0);
  });
  ASSERT_EQ(sim.advance(0.1).kind, RunStatus::Kind::Completed);
  EXPECT_EQ(at, (std::vector<double>{0.025, 0.05, 0.07500000000000001}));  // (none at t_end)
  Case bdf = cs;
  bdf.sim.options.kind = IntegratorKind::Bdf;
  try {
    run_controlled(bdf, one_thread(), [](double, const Snapshot&) { return ControlOutput{}; }, ControlOptions{0.01, 0, {}});
    FAIL() << "BDF accepted";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("simulation.integrator"), std::string::npos) << e.what();
  }
  Simulation stepped(bdf, one_thread());
  EXPECT_THROW(stepped.sample_every(0.01, 1, [](double) {}), std::logic_error);
}
