// The HAC statistics of every identify() (issue 9, issue 30 item 1).
// - BM_FixedBCriticalValue*: a fixed-seed simulation of 2000 Brownian-bridge functionals on 1000
//   steps, once per process for each (level, window) (...FirstCall); later calls are a look-up
//   (...Known).
// - BM_BartlettLongRunCovariance: the HAC meat of T samples' p-dimensional scores with the
//   automatic window's floor, L = 0.02·T lags; by window sums it grows as T·p², not L·T·p².
// Run: ./build/bench/statistics_bench
#include <random>

#include <benchmark/benchmark.h>
#include <Eigen/Dense>

#include "dynid/estimation/statistics.hpp"

namespace {

// The simulation itself: every call asks for a level not seen before (the value is kept per
// level and window, and the simulation's cost does not depend on the level).
void BM_FixedBCriticalValueFirstCall(benchmark::State& state) {
  const double b = static_cast<double>(state.range(0)) / 1000.0;
  double level = 0.999;
  for (auto _ : state) {
    level -= 1e-9;
    benchmark::DoNotOptimize(dynid::fixed_b_critical_value(level, b));
  }
}
BENCHMARK(BM_FixedBCriticalValueFirstCall)->Arg(20)->Arg(500)->Unit(benchmark::kMillisecond);

// Every later call for the same level and window: a look-up.
void BM_FixedBCriticalValueKnown(benchmark::State& state) {
  benchmark::DoNotOptimize(dynid::fixed_b_critical_value(0.999, 0.02));
  for (auto _ : state) benchmark::DoNotOptimize(dynid::fixed_b_critical_value(0.999, 0.02));
}
BENCHMARK(BM_FixedBCriticalValueKnown)->Unit(benchmark::kMicrosecond);

void BM_BartlettLongRunCovariance(benchmark::State& state) {
  const Eigen::Index T = state.range(0), p = state.range(1);
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd G(T, p);
  for (Eigen::Index i = 0; i < G.size(); ++i) G.data()[i] = n01(rng);
  const int L = static_cast<int>(0.02 * static_cast<double>(T));
  for (auto _ : state) {
    const Eigen::MatrixXd S = dynid::bartlett_long_run_covariance(G, L);
    benchmark::DoNotOptimize(S.data());
  }
  state.SetItemsProcessed(state.iterations() * T);  // samples per second
}
BENCHMARK(BM_BartlettLongRunCovariance)
    ->ArgNames({"samples", "p"})
    ->Args({10000, 60})
    ->Args({100000, 60})
    ->Args({1000000, 60})
    ->Args({100000, 10})
    ->Args({100000, 200})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
