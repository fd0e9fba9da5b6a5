// Microbenchmarks (Google Benchmark) of the per-step kernels on the paper's manipulator with its
// flexible link cut into n rfes: one residual evaluation (generalised forces), one Newton-matrix
// assembly, one CHOLMOD refactorisation, one solve. Arguments: {n, threads}.
// Pin threads for stable timings: OMP_PROC_BIND=close OMP_PLACES=cores (see bench/README.md).
#include <benchmark/benchmark.h>
#include <omp.h>

#include <random>

#include "assembly/assemble.hpp"
#include "cases/case_file.hpp"
#include "solvers/newton_system.hpp"

using namespace rfem;

namespace {

struct Setup {
  Model model;
  VecX q, v, a;
  std::vector<int> base_col;
  explicit Setup(int n)
      : model(build_model(read_case(std::string(BENCH_SOURCE_DIR) + "/cases/paper_deployment.toml"), n)) {
    std::mt19937 gen(1);
    std::uniform_real_distribution<double> u(-1, 1);
    const int N = model.dof();
    q = v = a = VecX::Zero(N);
    for (int i = 0; i < N; ++i) {
      const bool base = i >= 6 * n;
      q[i] = (base ? 1.0 : 1e-3) * u(gen);
      v[i] = (base ? 0.3 : 1e-2) * u(gen);
      a[i] = u(gen);
    }
    for (int j = 0; j < model.m(); ++j) base_col.push_back(6 * n + j);  // force input: all joints free
  }
};

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
  for (auto _ : state) {
    generalised_forces(s.model, s.q, s.v, s.a, ForceTerms{}, F);
    benchmark::DoNotOptimize(F.data());
  }
  per_rfe(state);
}

void BM_NewtonAssembly(benchmark::State& state) {
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  const BorderedPattern p(s.model.n(), s.model.m());
  MatrixTerms t;
  t.mass = 1e4;
  t.damping = 1e2;
  t.stiffness = 1.0;
  std::vector<double> vals;
  for (auto _ : state) {
    assemble_matrix(s.model, p, s.base_col, s.q, s.v, t, vals);
    benchmark::DoNotOptimize(vals.data());
  }
  per_rfe(state);
}

void BM_NewtonSetup(benchmark::State& state) {  // assembly of S and K + CHOLMOD refactorisation
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  NewtonSystem ns(s.model, s.base_col, s.model.m());
  for (auto _ : state) benchmark::DoNotOptimize(ns.setup(s.q, s.v, 100.0));
  per_rfe(state);
}

void BM_Factorize(benchmark::State& state) {
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  const BorderedPattern p(s.model.n(), s.model.m());
  MatrixTerms t;
  t.mass = 1e4;
  t.stiffness = 1.0;
  std::vector<double> vals;
  assemble_matrix(s.model, p, s.base_col, s.q, s.v, t, vals);
  CholmodSolver solver(p);
  for (auto _ : state) benchmark::DoNotOptimize(solver.factorize(vals));
  per_rfe(state);
}

void BM_NewtonSolve(benchmark::State& state) {
  threads(state);
  Setup s(static_cast<int>(state.range(0)));
  NewtonSystem ns(s.model, s.base_col, s.model.m());
  ns.setup(s.q, s.v, 100.0);
  const int u = ns.size();
  VecX b = VecX::Ones(2 * u), x(2 * u);
  for (auto _ : state) {
    ns.solve(b.data(), x.data());
    benchmark::DoNotOptimize(x.data());
  }
  per_rfe(state);
}

void args(benchmark::internal::Benchmark* b) {
  for (int n : {10, 100, 1000, 10000})
    for (int t : {1, 2}) b->Args({n, t});
  b->Unit(benchmark::kMicrosecond)->UseRealTime();
}

}  // namespace

BENCHMARK(BM_Residual)->Apply(args);
BENCHMARK(BM_NewtonAssembly)->Apply(args);
BENCHMARK(BM_NewtonSetup)->Apply(args);
BENCHMARK(BM_Factorize)->Apply(args);
BENCHMARK(BM_NewtonSolve)->Apply(args);
BENCHMARK_MAIN();
