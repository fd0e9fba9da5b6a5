// rfem as a library: what a C++ caller relies on beyond the physics. Results kept in memory equal
// what the HDF5 recorder writes; a stop token ends one run and not the next; an EquationsOfMotion
// moved to another object computes the same residual; wrong sizes and bad invariants are refused
// at the entry points; a run's status survives its round trip through text.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "../assembly/assemble.hpp"
#include "../results/reader.hpp"
#include "../simulation/inputs.hpp"
#include "../simulation/recorders.hpp"
#include "../solvers/equations.hpp"
#include "../solvers/mass_solve.hpp"
#include "../solvers/statics.hpp"
#include "../studies/runs.hpp"
#include "tests/test_models.hpp"

using namespace rfem;

namespace {
Case spinup(double t_end) {
  return with_overrides(read_case(test::source_path("cases/kane_spinup.toml")),
                        {"simulation.t_end=" + std::to_string(t_end), "link.n=8"});
}
}  // namespace

TEST(Library, SeriesInMemoryEqualTheResultsFile) {
  const Case cs = spinup(1.0);
  const std::string path = (std::filesystem::temp_directory_path() / "rfem_library_test.h5").string();
  std::vector<RunResult> runs;
  {
    ResultsWriter file(path, describe(cs, "test", "single", 8, 1));
    Hdf5Recorder rec(file);
    RunRequest rq;
    rq.threads = 1;
    rq.observers = {&rec};
    runs = run_case(cs, rq);
    file.close();
  }
  ASSERT_EQ(runs.size(), 1u);
  const RunResult& r = runs[0];
  ASSERT_TRUE(r.completed()) << r.status;
  EXPECT_EQ(r.samples, 21);  // t = 0, 0.05, …, 1
  const ResultsReader f(path);
  EXPECT_EQ(f.attribute("run", "status"), "completed");
  for (const std::string name : {"time", "joint_q", "joint_tau", "energy", "tip_deflection", "links/link/tip"}) {
    const Table a = r.series->table(name), b = f.table("run/" + name);
    ASSERT_EQ(a.rows, b.rows) << name;
    ASSERT_EQ(a.cols, b.cols) << name;
    EXPECT_EQ(a.data, b.data) << name;  // the same numbers, bit for bit
  }
  // The peaks of the summary are the series' maxima.
  const Table u = r.series->table("tip_deflection");
  double peak = 0.0;
  for (long i = 0; i < u.rows; ++i) peak = std::max(peak, std::abs(u.at(i, 0)));
  EXPECT_EQ(peak, r.peaks[0].u1);
  std::filesystem::remove(path);
}

TEST(Library, StopTokenEndsOneRunWithinAStepAndNotTheNext) {
  const Case cs = spinup(4.0);
  RunRequest rq;
  rq.threads = 1;
  rq.progress_interval = 0.0;  // every step
  double stopped_at = -1.0;
  rq.progress = [&](const Progress& p) {
    if (p.t > 0.5 && stopped_at < 0) {
      stopped_at = p.t;
      rq.stop.request(15);
    }
  };
  const auto first = run_case(cs, rq);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].status.to_string(), "interrupted (signal 15)");
  // Every output before the stop is kept, none after it: the last output lies within a step of it.
  EXPECT_LE(first[0].t_reached, stopped_at + 1e-12);
  EXPECT_GT(first[0].t_reached, stopped_at - 0.1);
  EXPECT_EQ(first[0].samples, first[0].series->rows);
  rq.stop.reset();
  rq.progress = nullptr;
  const auto second = run_case(cs, rq);
  EXPECT_TRUE(second[0].completed()) << second[0].status;
  // The first run's outputs are the second's (the stop changed nothing before it).
  const Table a = first[0].series->table("joint_tau"), b = second[0].series->table("joint_tau");
  for (long i = 0; i < a.rows; ++i) EXPECT_EQ(a.at(i, 0), b.at(i, 0));
}

TEST(Library, MovedEquationsComputeTheSameResidual) {
  const auto model = std::make_shared<const Model>(test::spatial_arm(6, 1e-3));
  std::vector<JointInput> inputs(model->m());
  for (auto& in : inputs) in.torque = constant_torque(0.3);
  EquationsOfMotion a(model, inputs, ForceTerms{});
  VecX q, v;
  a.initial_state(q, v);
  q.head(model->flexible_dofs()).setConstant(1e-4);
  const VecX acc = VecX::LinSpaced(a.unknowns(), -1.0, 1.0);
  VecX r0(a.unknowns()), r1(a.unknowns());
  a.residual(0.1, q.data(), v.data(), acc.data(), r0.data());
  ASSERT_TRUE(a.setup_newton(0.1, q.data(), v.data(), 1e-3));
  EquationsOfMotion b(std::move(a));  // the Newton system and workspace move with it
  b.residual(0.1, q.data(), v.data(), acc.data(), r1.data());
  EXPECT_EQ((r0 - r1).cwiseAbs().maxCoeff(), 0.0);
  ASSERT_TRUE(b.setup_newton(0.1, q.data(), v.data(), 1e-3));
  VecX x = r1;
  b.solve_newton(x);
  EXPECT_TRUE(x.allFinite());
}

TEST(Library, EntryPointsRefuseWrongSizesAndBadInvariants) {
  const Model m = test::spatial_arm(4);
  VecX F;
  const VecX short_q = VecX::Zero(m.dof() - 1), q = VecX::Zero(m.dof());
  EXPECT_THROW(generalised_forces(m, short_q, q, q, ForceTerms{}, F), std::invalid_argument);
  EXPECT_THROW(energies(m, q, short_q), std::invalid_argument);
  EXPECT_THROW(tip_motion(m, 3, q), std::invalid_argument);
  EXPECT_THROW(tabulated_motion({0, 1, 2}, {0, 1}), std::invalid_argument);  // unequal columns
  Joint j;
  j.drive.friction = 1.0;
  j.drive.friction_velocity = 0.0;  // tanh(v/0): the type refuses it
  EXPECT_THROW(make_model({j}, Mat4::Identity(), Discretisation{}, 0.0), std::invalid_argument);
  FlexibleLink bad;
  bad.segments.push_back(Segment{1.0, Material{"m", -1.0, 1.0, 1.0}, Section{}, 1});
  EXPECT_THROW(discretise(bad), std::invalid_argument);
  IntegratorOptions o;
  o.t_end = 1.0;
  o.output_dt = 1e-19;  // 1e19 outputs
  EXPECT_THROW(check_options(o), std::invalid_argument);
}

TEST(Library, SolversRefuseWrongSizesAndMissingBuffers) {
  // Each call would read or write past a buffer without its check.
  const auto model = std::make_shared<const Model>(test::spatial_arm(4));
  const Model& m = *model;
  std::vector<int> cols(m.m());
  for (int j = 0; j < m.m(); ++j) cols[j] = m.flexible_dofs() + j;  // every joint free, after the rfes
  const BorderedPattern p(m, cols);
  const VecX q = VecX::Zero(m.dof());
  std::vector<double> values(p.nnz(), 0.0), short_values(p.nnz() - 1, 0.0);
  VecX b = VecX::Zero(p.size()), short_b = VecX::Zero(p.size() - 1), y;
  EXPECT_THROW(solve_mass(m, p, cols, q, q, short_b, values), std::invalid_argument);
  EXPECT_THROW(solve_mass(m, p, {0}, q, q, b, values), std::invalid_argument);
  EXPECT_THROW(solve_mass(m, p, cols, q.head(3), q, b, values), std::invalid_argument);
  EXPECT_THROW(p.multiply(short_values, b, y), std::invalid_argument);
  EXPECT_THROW(p.multiply(values, short_b, y), std::invalid_argument);
  EXPECT_THROW(to_dense(p, short_values), std::invalid_argument);
  EXPECT_THROW(tip_generalised_force(m, static_cast<int>(m.links.size()), Vec6::Zero(), TipLoads{}), std::invalid_argument);
  EXPECT_THROW(tip_generalised_force(m, -1, Vec6::Zero(), TipLoads{}), std::invalid_argument);
  std::vector<JointInput> inputs(m.m());
  for (auto& in : inputs) in.torque = constant_torque(0.0);
  EquationsOfMotion eq(model, inputs, ForceTerms{}, StopToken{}, LinearSolverKind::Chain, Parallelism{}, true);  // (K kept: IDA's solve)
  VecX qu, vu;
  eq.initial_state(qu, vu);
  VecX r(eq.unknowns());
  EXPECT_THROW(eq.residual(0.0, nullptr, vu.data(), nullptr, r.data()), std::invalid_argument);
  EXPECT_THROW(eq.residual(0.0, qu.data(), vu.data(), nullptr, nullptr), std::invalid_argument);
  EXPECT_THROW(eq.setup_newton(0.0, qu.data(), vu.data(), 0.0), std::invalid_argument);
  EXPECT_THROW(eq.setup_newton(0.0, qu.data(), vu.data(), NAN), std::invalid_argument);
  EXPECT_THROW(eq.power_change(0.0, vu.data(), VecX::Zero(eq.unknowns() + 1), 1e-3), std::invalid_argument);
  std::vector<double> x2(2 * eq.unknowns()), b2(2 * eq.unknowns());
  EXPECT_THROW(eq.solve_newton_bdf(b2.data(), x2.data()), std::invalid_argument);  // no setup yet
  ASSERT_TRUE(eq.setup_newton(0.0, qu.data(), vu.data(), 1e-3));
  EXPECT_THROW(eq.solve_newton_bdf(nullptr, x2.data()), std::invalid_argument);
  EXPECT_NO_THROW(eq.solve_newton_bdf(b2.data(), x2.data()));
  // A workspace built for one model refuses another (the chunks would index past its links).
  Workspace bound(m);
  const Model other = test::spatial_arm(6);
  const VecX qo = VecX::Zero(other.dof());
  VecX F;
  EXPECT_THROW(generalised_forces(other, qo, qo, qo, ForceTerms{}, F, nullptr, &bound), std::invalid_argument);
  EXPECT_THROW(energies(other, qo, qo, &bound), std::invalid_argument);
  EXPECT_NO_THROW(generalised_forces(m, q, q, q, ForceTerms{}, F, nullptr, &bound));
}

TEST(Library, RunStatusSurvivesItsText) {
  for (const RunStatus& s : {RunStatus{}, RunStatus::completed(), RunStatus::interrupted(2), RunStatus::interrupted(0),
                             RunStatus::failed("step size underflow at t = 1 s")}) {
    const RunStatus p = RunStatus::parse(s.to_string());
    EXPECT_EQ(p.kind, s.kind);
    EXPECT_EQ(p.signal, s.signal);
    EXPECT_EQ(p.reason, s.reason);
  }
}
