// Resuming runs from their checkpoints (studies/resume.hpp): the paper's procedure stopped in its
// kinematic run and resumed from the results file gives every series and quantity of the
// uninterrupted procedure bit for bit (ESDIRK, one thread: the same arithmetic in the same order);
// the integrator's state survives packing; a checkpoint of another model is refused.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "../results/writer.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../simulation/simulation.hpp"
#include "../studies/quantities.hpp"
#include "../studies/resume.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {

constexpr int kN = 12;
Case paper() { return read_case(test::source_path("cases/paper_deployment.toml"), {"simulation.t_end=3.0"}); }

// Requests a stop at the k-th sample of run `run`.
class StopAt : public RunObserver {
 public:
  StopAt(StopToken stop, std::string run, long k) : stop_(std::move(stop)), run_(std::move(run)), k_(k) {}
  void begin(const RunInfo& info) override { current_ = info.name, seen_ = 0; }
  void sample(const OutputSample&) override {
    if (current_ == run_ && ++seen_ == k_) stop_.request();
  }

 private:
  StopToken stop_;
  std::string run_, current_;
  long k_, seen_ = 0;
};

std::vector<Quantity> quantities(const Case& cs) {
  return {parse_quantity(cs, "kinematic/peak:u1"), parse_quantity(cs, "force/peak:u2"), parse_quantity(cs, "rigid/tau3@2")};
}

std::string temp_file(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("rfem_test_resume_" + std::to_string(::getpid()) + "_" + name)).string();
}

// Kane's beam on a hub under a digital PD with a delay of two samples (held values are the law's
// memory, not the integrator's), 6 rfes.
Case digital_pd_hub(double t_end) {
  return read_case(test::source_path("cases/kane_hub_drive.toml"),
                   {"link.n=6", "simulation.t_end=" + std::to_string(t_end), "simulation.output_dt=0.01",
                    "joints.0.input={kind=\"pd\", reference={kind=\"spinup\", Omega=1.0, T=2.0}, kp=4.0e4, kd=1.2e4, "
                    "sample_time=1e-3, delay=2}"});
}

RunRequest one_thread() {
  RunRequest rq;
  rq.threads = 1;
  return rq;
}

// A results file of the case's procedure at n rfes (one thread, a checkpoint after every step or
// output) stopped at the k-th output of run `run`, as an interrupted `rfem run` leaves it.
std::string stopped_run_file(const Case& cs, int n, const std::string& run, long k, const std::string& name) {
  const std::string path = temp_file(name);
  const auto model = model_of(cs, n);
  ResultsWriter file(path, describe(cs, "test_resume", cs.sim.procedure == Procedure::Paper ? "paper" : "single", model->n(), 1, n));
  Hdf5Recorder recorder(file);
  RunRequest rq;
  rq.n = n;
  rq.threads = 1;
  rq.keep_series = false;
  rq.checkpoint_interval = 1e-9;
  StopAt stop(rq.stop, run, k);
  rq.observers = {&recorder, &stop};
  EXPECT_EQ(run_case(cs, model, joint_inputs(cs, {}), rq).back().status.kind, RunStatus::Kind::Interrupted);
  file.close();
  return path;
}

}  // namespace

TEST(Resume, PaperProcedureStoppedInItsKinematicRunEndsBitForBitAsUninterrupted) {
  const Case cs = paper();
  RunRequest whole;
  whole.n = kN;
  whole.threads = 1;
  QuantityRecorder q_whole(quantities(cs));
  whole.observers = {&q_whole};
  const std::vector<RunResult> ref = run_case(cs, whole);
  ASSERT_EQ(ref.size(), 3u);
  ASSERT_TRUE(ref.back().completed());

  // Stopped at the 120th output of the kinematic run, a checkpoint after every step.
  const std::string path = temp_file("paper.h5");
  const auto model = model_of(cs, kN);
  QuantityRecorder q_first(quantities(cs));
  {
    ResultsWriter file(path, describe(cs, "test_resume", "paper", model->n(), 1, kN));
    Hdf5Recorder recorder(file);
    RunRequest rq;
    rq.n = kN;
    rq.threads = 1;
    rq.keep_series = false;
    rq.checkpoint_interval = 1e-9;
    StopAt stop(rq.stop, "kinematic", 120);
    rq.observers = {&recorder, &q_first, &stop};
    const std::vector<RunResult> runs = run_case(cs, model, joint_inputs(cs, {}), rq);
    ASSERT_EQ(runs.size(), 2u);
    EXPECT_EQ(runs.back().status.kind, RunStatus::Kind::Interrupted);
    file.close();
  }
  const ResumePlan plan = plan_resume(path);
  EXPECT_EQ(plan.n, kN);
  EXPECT_EQ(plan.done, std::vector<std::string>{"rigid"});
  ASSERT_EQ(plan.resume.count("kinematic"), 1u);
  EXPECT_EQ(plan.resume.at("kinematic").rows, 120);
  EXPECT_FALSE(plan.finished());

  RunRequest rq;
  rq.threads = 1;
  QuantityRecorder q_resumed(quantities(cs));  // (its series of the rigid run come from the checkpoint)
  rq.observers = {&q_resumed};
  const std::vector<RunResult> rest = resume_case(plan, rq);
  ASSERT_EQ(rest.size(), 2u);
  for (size_t r = 0; r < 2; ++r) {
    const RunResult& a = ref[r + 1];
    const RunResult& b = rest[r];
    ASSERT_EQ(a.name, b.name);
    ASSERT_TRUE(b.completed()) << b.status.to_string();
    EXPECT_EQ(a.stats.steps, b.stats.steps) << a.name;
    EXPECT_EQ(a.stats.residual_evals, b.stats.residual_evals) << a.name;
    EXPECT_EQ(a.samples, b.samples) << a.name;
    EXPECT_EQ(a.peaks[0].u1, b.peaks[0].u1) << a.name;
    EXPECT_EQ(a.energy_drift, b.energy_drift) << a.name;
    for (const std::string& name : a.series->names()) {
      const Table x = a.series->table(name), y = b.series->table(name);
      EXPECT_EQ(x.rows, y.rows) << a.name << "/" << name;
      EXPECT_TRUE(x.data == y.data) << a.name << "/" << name << " differs";
    }
  }
  const std::vector<double> v0 = q_whole.values(), v1 = q_resumed.values();
  ASSERT_EQ(v0.size(), 3u);
  for (size_t k = 0; k < v0.size(); ++k) {
    EXPECT_TRUE(std::isfinite(v0[k]));
    EXPECT_EQ(v0[k], v1[k]) << "quantity " << k;
  }
  EXPECT_TRUE(plan_resume(path).finished());
  EXPECT_TRUE(resume_case(plan_resume(path), rq).empty());

  // The same file with another model: its series do not fit, nothing is run.
  ResumePlan other = plan_resume(path);
  other.n = 2 * kN;
  other.done.clear();
  other.resume.emplace("rigid", Checkpoint{});
  EXPECT_THROW(resume_case(other, RunRequest{}), std::exception);
  std::filesystem::remove(path);
}

TEST(Resume, ADigitalPdGoesOnFromItsHeldAndDelayedValues) {
  // A digital PD with a delay of two samples (held values are the law's memory, not the
  // integrator's): stopped at an output and resumed from its checkpoint, the run ends bit for bit
  // as the uninterrupted one (it would not if the held or delayed torques restarted from zero).
  const Case cs = digital_pd_hub(1.0);
  const RunResult ref = run_case(cs, one_thread()).at(0);
  ASSERT_TRUE(ref.completed()) << ref.status;
  const std::string path = stopped_run_file(cs, 6, "run", 37, "digital.h5");
  const ResumePlan plan = plan_resume(path);
  ASSERT_EQ(plan.resume.count("run"), 1u);
  RunRequest rq;
  rq.threads = 1;
  const RunResult rest = resume_case(plan, rq).at(0);
  ASSERT_TRUE(rest.completed()) << rest.status;
  EXPECT_EQ(ref.stats.steps, rest.stats.steps);
  for (const char* name : {"joint_q", "joint_tau", "tip_deflection"}) {
    const Table x = ref.series->table(name), y = rest.series->table(name);
    EXPECT_TRUE(x.data == y.data) << name << " differs";
  }
  std::filesystem::remove(path);
}

TEST(Resume, IntegratorStateRoundTripsAndRefusesAnotherModel) {
  IntegratorState s;
  s.t = 1.25;
  s.h = 3e-3;
  s.err_prev = 0.4;
  s.eta = 0.01;
  s.dissipated = 0.5;
  s.input_work = 2.5;
  s.power = {0.1, -0.2};
  s.next_output = 7;
  s.stats.steps = 123456789012;
  s.stats.newton_fails = 3;
  s.stats.last_step = 1e-3;
  s.q = VecX::LinSpaced(5, -1, 1);
  s.v = VecX::Constant(5, M_PI);
  s.a = VecX::Constant(5, -1e300);
  const IntegratorState r = IntegratorState::unpack(s.pack(), 5);
  EXPECT_EQ(r.pack(), s.pack());
  EXPECT_EQ(r.stats.steps, 123456789012);
  EXPECT_EQ(r.next_output, 7);
  EXPECT_THROW(IntegratorState::unpack(s.pack(), 6), std::invalid_argument);
  std::vector<double> cut = s.pack();
  cut.pop_back();
  EXPECT_THROW(IntegratorState::unpack(cut, 5), std::invalid_argument);
  // A damaged or edited state is refused naming its entry (not at the first step): a NaN
  // coordinate, a NaN or fractional counter, a negative time.
  const size_t head = s.pack_head().size();
  auto refused = [&](size_t i, double value) {
    std::vector<double> x = s.pack();
    x[i] = value;
    try {
      IntegratorState::unpack(x, 5);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(refused(head, NAN).find("q[0] is not finite"), std::string::npos);
  EXPECT_NE(refused(head + 5 + 2, INFINITY).find("v[2] is not finite"), std::string::npos);
  EXPECT_NE(refused(10, NAN).find("steps"), std::string::npos);
  EXPECT_NE(refused(9, 2.5).find("next_output"), std::string::npos);
  EXPECT_NE(refused(1, -1.0).find("negative"), std::string::npos);
  EXPECT_NE(refused(2, NAN).find("h is not finite"), std::string::npos);
  EXPECT_EQ(refused(2, INFINITY), "accepted");  // (a controller's frequent stops let the proposal grow unbounded)
  EXPECT_NE(refused(head - 1, 4.0).find("4 unknowns, the model 5"), std::string::npos);
}

// A run with noisy sensors, stopped and resumed, has every
// sensor row of the uninterrupted run, the same noise bit for bit (the checkpoint holds the
// streams); a run stepped by its caller (a controller in the loop) is refused by resume, the file
// left as it was.
TEST(Resume, NoisySensorsResumeBitForBitAndASteppedRunIsRefused) {
  std::string text;
  {
    std::ifstream in(test::source_path("cases/paper_deployment.toml"));
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  text += "\n[[sensors]]\nname = \"enc\"\nkind = \"encoder\"\njoint = \"psi3\"\nnoise = 1e-3\n";
  const Case cs = parse_case(text, test::source_path("cases/paper_deployment.toml"), {"simulation.t_end=1.0"});
  RunRequest whole;
  whole.n = 6;
  whole.threads = 1;
  const std::vector<RunResult> ref = run_case(cs, whole);
  ASSERT_EQ(ref.size(), 3u);
  const std::string path = temp_file("sensors.h5");
  {
    const auto model = model_of(cs, 6);
    ResultsWriter file(path, describe(cs, "test_resume", "paper", model->n(), 1, 6));
    Hdf5Recorder recorder(file);
    RunRequest rq;
    rq.n = 6;
    rq.threads = 1;
    rq.checkpoint_interval = 1e-9;
    StopAt stop(rq.stop, "kinematic", 40);
    rq.observers = {&recorder, &stop};
    const std::vector<RunResult> runs = run_case(cs, model, joint_inputs(cs, {}), rq);
    ASSERT_EQ(runs.back().status.kind, RunStatus::Kind::Interrupted);
    file.close();
  }
  RunRequest rq;
  rq.threads = 1;
  const std::vector<RunResult> rest = resume_case(plan_resume(path), rq);
  ASSERT_EQ(rest.size(), 2u);
  const ResultsReader in(path);
  for (size_t r = 0; r < 2; ++r) {
    const RunResult& a = ref[r + 1];
    ASSERT_TRUE(rest[r].completed()) << rest[r].status;
    const Table file_rows = in.table(a.name + "/sensors");
    EXPECT_EQ(file_rows.rows, a.sensors.rows) << a.name;
    EXPECT_TRUE(file_rows.data == a.sensors.data) << a.name << ": the sensor rows differ from the uninterrupted run's";
    EXPECT_TRUE(rest[r].sensors.data == a.sensors.data) << a.name << ": the resumed run's own sensor rows";
  }
  std::filesystem::remove(path);

  // A stepped run's file (rfem::Simulation) is not resumed: its inputs are not in the file.
  const std::string stepped = temp_file("stepped.h5");
  {
    SimulationOptions o;
    o.threads = 1;
    o.output = stepped;
    o.n = 6;
    Simulation s(cs, o);
    s.advance(0.1);
  }
  const auto before = std::filesystem::last_write_time(stepped);
  try {
    plan_resume(stepped);
    ADD_FAILURE() << "a stepped run's file was accepted for resume";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("stepped by rfem::Simulation"), std::string::npos) << e.what();
  }
  EXPECT_EQ(std::filesystem::last_write_time(stepped), before);
  std::filesystem::remove(stepped);
}

// One state format: a checkpoint holds the run's SimulationState. With BDF every checkpoint is at an
// output the run recorded, so the state's sensor streams are those before that row (as a state
// taken there by a caller): the resumed run draws that row's noise past (SensorBank::skip) and
// every later row reads the uninterrupted run's noise. The encoder reads the prescribed spin-up,
// exact in both runs, so the rows agree bit for bit only if the noise does (a stream one row
// behind differs by the noise itself, 1e-3).
TEST(Resume, ACheckpointAtARecordedRowGoesOnWithTheSameSensorNoise) {
  const Case cs = read_case(test::source_path("cases/kane_spinup.toml"),
                            {"link.n=6", "simulation.t_end=1.0", "simulation.output_dt=0.01", "simulation.integrator=\"bdf\"",
                             "sensors=[{name=\"enc\", kind=\"encoder\", joint=\"hub\", noise=1e-3}]"});
  RunRequest whole;
  whole.threads = 1;
  const RunResult ref = run_case(cs, whole).at(0);
  ASSERT_TRUE(ref.completed()) << ref.status;
  const std::string path = stopped_run_file(cs, 6, "run", 43, "bdf_sensors.h5");
  const ResumePlan plan = plan_resume(path);
  ASSERT_EQ(plan.resume.count("run"), 1u);
  const RunState at = RunState::unpack(plan.resume.at("run").state);
  const long k = at.state.integrator.next_output - 1;
  ASSERT_EQ(output_time(cs.sim.options, k), at.state.time()) << "the BDF checkpoint is not at an output";
  RunRequest rq;
  rq.threads = 1;
  ASSERT_TRUE(resume_case(plan, rq).at(0).completed());
  const Table rows = ResultsReader(path).table("run/sensors");
  ASSERT_EQ(rows.rows, ref.sensors.rows);
  EXPECT_TRUE(rows.data == ref.sensors.data) << "the resumed rows' noise differs from the uninterrupted run's";
  std::filesystem::remove(path);
}

// A killed run's checkpoint is a simulation's state: a Simulation started from it (as from a state
// a caller took) goes on bit for bit as the uninterrupted run with ESDIRK, the digital PD's held
// and delayed torques included; a file of the paper's procedure (three runs) is refused by name.
TEST(Resume, AKilledRunsCheckpointIsASimulationState) {
  const Case cs = digital_pd_hub(0.6);
  const RunResult ref = run_case(cs, one_thread()).at(0);
  ASSERT_TRUE(ref.completed()) << ref.status;
  const std::string path = stopped_run_file(cs, 6, "run", 29, "killed.h5");
  const SimulationState st = read_state(path);
  EXPECT_EQ(st.model, model_signature(*model_of(cs, 6), joint_inputs(cs, {})));
  EXPECT_GT(st.time(), 0.27);
  EXPECT_FALSE(st.laws.empty());
  SimulationOptions o;
  o.threads = 1;
  o.keep_series = true;
  o.state = std::make_shared<const SimulationState>(st);
  Simulation sim(cs, o);
  sim.advance(sim.t_end());
  const RunResult rest = sim.finish();
  ASSERT_TRUE(rest.completed()) << rest.status;
  // The state's own row first (off the output grid), then the outputs after it: the reference's last rows.
  const Table x = ref.series->table("joint_tau"), y = rest.series->table("joint_tau");
  const long later = y.rows - 1;
  ASSERT_GT(later, 10);
  ASSERT_EQ(x.cols, y.cols);
  EXPECT_TRUE(std::equal(x.data.end() - later * x.cols, x.data.end(), y.data.end() - later * y.cols))
      << "the run from the checkpoint's state differs from the uninterrupted one";
  std::filesystem::remove(path);

  const std::string paper_file = stopped_run_file(paper(), 6, "kinematic", 10, "paper_killed.h5");
  try {
    read_state(paper_file);
    ADD_FAILURE() << "a paper procedure's file was read as one simulation's state";
  } catch (const CaseError& e) {
    EXPECT_NE(std::string(e.what()).find("a simulation's state is a single run's"), std::string::npos) << e.what();
  }
  std::filesystem::remove(paper_file);
}
