// Fixed-b critical value of the HAC intervals (fixed_b_critical_value): a fixed-seed simulation of
// 2000 Brownian-bridge functionals on 1000 steps, run once per identify() (issue 9). Its cost
// does not depend on the run; b changes only the window of the partial-sum product.
// Run: ./build/bench/statistics_bench
#include <benchmark/benchmark.h>

#include "dynid/estimation/statistics.hpp"

namespace {

void BM_FixedBCriticalValue(benchmark::State& state) {
  const double b = static_cast<double>(state.range(0)) / 1000.0;
  for (auto _ : state) benchmark::DoNotOptimize(dynid::fixed_b_critical_value(0.999, b));
}
BENCHMARK(BM_FixedBCriticalValue)->Arg(20)->Arg(71)->Arg(500)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
