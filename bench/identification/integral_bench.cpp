// Integral-model equations (integral_equations) for 10⁵ and 10⁶ samples of the 7-DoF iiwa14 at
// 1 kHz, full friction layout, default options (10 ms intervals, endpoint-momentum row
// weights) (issue 11 item 8): samples per second of the
// equations stage alone (the run is an in-memory processed record; reading and filtering are
// measured by identification_bench). Run: ./build/bench/integral_bench
#include <cmath>

#include <benchmark/benchmark.h>

#include "dynid/identification/integral_equations.hpp"
#include "dynid/model/robots.hpp"

namespace {

dynid::ProcessedRecord record(int n, long samples) {
  dynid::ProcessedRecord p;
  p.rate_hz = 1000.0;
  p.record.t.resize(samples);
  p.record.q.resize(samples, n);
  p.record.dq.resize(samples, n);
  p.record.tau.resize(samples, n);
  p.velocity_noise_std = Eigen::VectorXd::Constant(n, 1e-3);  // enables the momentum weights
  for (long k = 0; k < samples; ++k) {
    const double t = 1e-3 * k;
    p.record.t[k] = t;
    for (int j = 0; j < n; ++j) {
      const double w = 0.4 + 0.2 * j;
      p.record.q(k, j) = 0.8 * std::sin(w * t + j);
      p.record.dq(k, j) = 0.8 * w * std::cos(w * t + j);
      p.record.tau(k, j) = 10.0 * std::sin(1.3 * w * t);
    }
  }
  return p;
}

void BM_IntegralEquations(benchmark::State& state) {
  const dynid::Model model = dynid::load_robot("iiwa14");
  const long samples = state.range(0);
  const dynid::ProcessedRecord p = record(model.dof(), samples);
  dynid::IntegralOptions o;
  o.long_integrals = state.range(1) != 0;
  for (auto _ : state) {
    const dynid::EquationBlock b =
        dynid::integral_equations(model, dynid::ParameterLayout::full(), true, p, o);
    benchmark::DoNotOptimize(b.y.data());
  }
  state.counters["samples_per_s"] = benchmark::Counter(
      static_cast<double>(samples), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_IntegralEquations)
    ->Args({100000, 0})
    ->Args({1000000, 0})
    ->Args({1000000, 1})
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
