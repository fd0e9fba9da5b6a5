// Microbenchmarks (Google Benchmark) of the per-step kernels on the paper's manipulator with its
// flexible link cut into n rfes: one residual evaluation (generalised forces), one assembly of the
// Newton matrix, assembly + factorisation (chain solver or CHOLMOD), one solve.
// Arguments: {n, threads[, solver: 0 chain, 1 CHOLMOD]}.
// BM_Links*: the cost per rfe of one flexible link of n rfes against two links of n/2 in a row
//: the two-link arm of cases/two_link_arm.toml (shoulder, upper link, elbow on its
// tip, forearm) and the same 2 m strip as one link of two segments on the shoulder. Arguments
// {n, links: 1 or 2}; one thread. A step is what an ESDIRK5 step costs: one Newton setup and 12
// residual evaluations with 12 solves.
// Pin threads for stable timings: OMP_PROC_BIND=close OMP_PLACES=cores (see bench/README.md).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <memory>
#include <random>

#include "../assembly/assemble.hpp"
#include "../cases/case_file.hpp"
#include "../core/rotation.hpp"
#include "../solvers/newton_system.hpp"

using namespace rfem;

namespace {

// A random state: deformation of scale `flex` [m, rad], moving joints.
void random_state(const Model& model, double flex, VecX& q, VecX& v, VecX& a) {
  std::mt19937 gen(1);
  std::uniform_real_distribution<double> u(-1, 1);
  const int N = model.dof();
  q = v = a = VecX::Zero(N);
  for (int i = 0; i < N; ++i) {
    const bool base = i >= model.flexible_dofs();
    q[i] = (base ? 1.0 : flex) * u(gen);
    v[i] = (base ? 0.3 : 1e-2) * u(gen);
    a[i] = u(gen);
  }
}

struct Setup {
  Model model;
  VecX q, v, a;
  std::vector<int> base_col;
  explicit Setup(int n)
      : model(build_model(read_case(std::string(BENCH_SOURCE_DIR) + "/cases/paper_deployment.toml"), n)) {
    // rfe coordinates of 1e-6 (m, rad): strains ≤ 1e-3 for rfes of 1 mm (n = 1 000). At 1e-3 the
    // rfes of n ≥ 1 000 would be strained 100 % and the Newton matrix indefinite.
    random_state(model, 1e-6, q, v, a);
    for (int j = 0; j < model.m(); ++j) base_col.push_back(model.joint_index(j));  // force input: all joints free
  }
};

// The two-link arm with n rfes in all, or the same strip as one link (both joints free), with a
// one-thread workspace and its Newton system.
struct LinksSetup {
  Model model;
  VecX q, v, a;
  std::vector<int> base_col;
  Workspace ws;
  std::unique_ptr<NewtonSystem> ns;
  explicit LinksSetup(const benchmark::State& state) {
    omp_set_num_threads(1);
    const int n = static_cast<int>(state.range(0));
    const Case c = read_case(std::string(BENCH_SOURCE_DIR) + "/cases/two_link_arm.toml");
    if (state.range(1) == 2) {
      model = build_model(c, n);
    } else {
      MountedLink L;
      L.name = "strip";
      FlexibleLink f = c.links[0].link;
      f.segments.push_back(c.links[1].link.segments[0]);
      f.segments[0].parts = n / 2;
      f.segments[1].parts = n - n / 2;
      L.d = discretise(f);
      model = make_model({c.joints[0]}, {L}, 0.0);
    }
    random_state(model, 1e-6, q, v, a);  // (a light strip: small deformation keeps S positive definite)
    for (int j = 0; j < model.m(); ++j) base_col.push_back(model.joint_index(j));
    ws.parallel.threads = 1;
    ns = std::make_unique<NewtonSystem>(std::make_shared<const Model>(model), base_col, LinearSolverKind::Chain);
  }
};

void per_rfe(benchmark::State& state);

// Newton solves with the system set up at the state (s: Setup or LinksSetup).
template <class S>
void solve_loop(benchmark::State& state, const S& s, NewtonSystem& ns, Workspace& ws) {
  if (!ns.setup(s.q, s.v, 0.005, ws)) state.SkipWithError("the Newton matrix is not positive definite");
  VecX b = VecX::Ones(ns.size()), x;
  const int team = ws.parallel.team(s.model.n());
  for (auto _ : state) {
    x = b;
    ns.solve(x, team);
    benchmark::DoNotOptimize(x.data());
  }
  per_rfe(state);
}

void BM_LinksResidual(benchmark::State& state) {
  LinksSetup s(state);
  VecX F;
  for (auto _ : state) {
    generalised_forces(s.model, s.q, s.v, s.a, ForceTerms{}, F, nullptr, &s.ws);
    benchmark::DoNotOptimize(F.data());
  }
  per_rfe(state);
}

void BM_LinksStep(benchmark::State& state) {
  LinksSetup s(state);
  VecX F, x;
  if (!s.ns->setup(s.q, s.v, 0.005, s.ws)) state.SkipWithError("the Newton matrix is not positive definite");
  for (auto _ : state) {
    benchmark::DoNotOptimize(s.ns->setup(s.q, s.v, 0.005, s.ws));
    for (int i = 0; i < 12; ++i) {
      generalised_forces(s.model, s.q, s.v, s.a, ForceTerms{}, F, nullptr, &s.ws);
      x = F.head(s.ns->size());
      s.ns->solve(x, 1);
      benchmark::DoNotOptimize(x.data());
    }
  }
  per_rfe(state);
}

void BM_LinksSetup(benchmark::State& state) {  // assembly + factorisation of S
  LinksSetup s(state);
  for (auto _ : state) benchmark::DoNotOptimize(s.ns->setup(s.q, s.v, 0.005, s.ws));
  per_rfe(state);
}

void BM_LinksSolve(benchmark::State& state) {
  LinksSetup s(state);
  solve_loop(state, s, *s.ns, s.ws);
}

void links_args(benchmark::internal::Benchmark* b) {
  for (int n : {100, 1000, 10000})
    for (int l : {1, 2}) b->Args({n, l});
  b->Unit(benchmark::kMicrosecond)->UseRealTime();
}

void threads(const benchmark::State& state) { omp_set_num_threads(static_cast<int>(state.range(1))); }

// Wall time per rfe per call [s] (shown with an SI prefix: "1.2u" = 1.2 µs).
void per_rfe(benchmark::State& state) {
  state.counters["per_rfe"] = benchmark::Counter(static_cast<double>(state.range(0)),
                                                 benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_Residual(benchmark::State& state) {
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  VecX F;
  Workspace ws;
  ws.parallel.threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    generalised_forces(s.model, s.q, s.v, s.a, ForceTerms{}, F, nullptr, &ws);
    benchmark::DoNotOptimize(F.data());
  }
  per_rfe(state);
}

// Assembly of S = M + hC + h²K and its factorisation (the Newton setup of every ESDIRK step);
// third argument: 0 chain solver, 1 CHOLMOD.
void BM_NewtonSetup(benchmark::State& state) {
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  NewtonSystem ns(std::make_shared<const Model>(s.model), s.base_col, state.range(2) ? LinearSolverKind::Cholmod : LinearSolverKind::Chain);
  Workspace ws;
  ws.parallel.threads = static_cast<int>(state.range(1));
  for (auto _ : state)
    if (!ns.setup(s.q, s.v, 0.005, ws)) {  // a failed factorisation stops early: not a timing
      state.SkipWithError("the Newton matrix is not positive definite");
      break;
    }
  per_rfe(state);
}

void BM_NewtonAssembly(benchmark::State& state) {  // S alone
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  const BorderedPattern p(s.model, s.base_col);
  MatrixTerms t;
  t.mass = 1.0;
  t.damping = 0.005;
  t.stiffness = 2.5e-5;
  std::vector<double> vals;
  Workspace ws;
  ws.parallel.threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    assemble_matrix(s.model, p, s.base_col, s.q, s.v, t, vals, &ws);
    benchmark::DoNotOptimize(vals.data());
  }
  per_rfe(state);
}

void BM_Solve(benchmark::State& state) {
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  NewtonSystem ns(std::make_shared<const Model>(s.model), s.base_col, state.range(2) ? LinearSolverKind::Cholmod : LinearSolverKind::Chain);
  Workspace ws;
  ws.parallel.threads = static_cast<int>(state.range(1));
  solve_loop(state, s, ns, ws);
}

void args(benchmark::internal::Benchmark* b) {
  for (int n : {10, 100, 1000, 10000})
    for (int t : {1, 2}) b->Args({n, t});
  b->Unit(benchmark::kMicrosecond)->UseRealTime();
}

void solver_args(benchmark::internal::Benchmark* b) {
  for (int n : {10, 100, 1000, 10000})
    for (int t : {1, 2})
      for (int k : {0, 1}) b->Args({n, t, k});
  b->Unit(benchmark::kMicrosecond)->UseRealTime();
}

}  // namespace

BENCHMARK(BM_Residual)->Apply(args);
BENCHMARK(BM_NewtonAssembly)->Apply(args);
BENCHMARK(BM_NewtonSetup)->Apply(solver_args);
BENCHMARK(BM_Solve)->Apply(solver_args);
BENCHMARK(BM_LinksResidual)->Apply(links_args);
BENCHMARK(BM_LinksSetup)->Apply(links_args);
BENCHMARK(BM_LinksSolve)->Apply(links_args);
BENCHMARK(BM_LinksStep)->Apply(links_args);
BENCHMARK_MAIN();
