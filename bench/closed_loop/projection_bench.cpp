// Stage 1 of the projection method (issue 13 item 3): a 6-joint run of 10⁵ samples, M1 = M2 = 50
// (6·101 + 1 = 607 FIR coefficients for each of 12 outputs), and the automatic order search on the
// same run. The reference is a 5-harmonic periodic signal per joint (seed 2's excitation), the
// torques a fixed FIR of it plus white noise.
// Run: ./build/bench/projection_bench --benchmark_repetitions=3
// --benchmark_report_aggregates_only=true
#include <cmath>
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/closed_loop/projection.hpp"

namespace {

struct Data {
  dynid::JointRecord run;
  Eigen::MatrixXd qr, dqr, ddqr;
};

Data make_data(long m, int n) {
  Data d;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g;
  const double ts = 0.005, w = 2 * M_PI * 0.1;
  d.run.t = Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) * ts);
  d.qr.resize(m, n);
  d.dqr.resize(m, n);
  d.ddqr.resize(m, n);
  for (long k = 0; k < m; ++k)
    for (int j = 0; j < n; ++j) {
      d.qr(k, j) = d.dqr(k, j) = d.ddqr(k, j) = 0.0;
      for (int h = 1; h <= 5; ++h) {
        const double x = h * w * d.run.t[k] + j + h;
        d.qr(k, j) += 0.2 / h * std::sin(x);
        d.dqr(k, j) += 0.2 * w * std::cos(x);
        d.ddqr(k, j) -= 0.2 * h * w * w * std::sin(x);
      }
    }
  d.run.q = d.qr;
  d.run.tau.resize(m, n);
  for (long k = 0; k < m; ++k)
    for (int j = 0; j < n; ++j) {
      d.run.q(k, j) += 1e-3 * g(rng);
      d.run.tau(k, j) = 10 * d.qr(k, j) + 0.1 * g(rng);
      if (k >= 3) d.run.tau(k, j) -= 4 * d.qr(k - 3, (j + 1) % n);
    }
  return d;
}

void given_orders(benchmark::State& state) {
  const Data d = make_data(100000, 6);
  dynid::ProjectionOptions o;
  o.m1 = o.m2 = 50;
  for (auto _ : state) {
    auto p = dynid::project_on_reference(d.run, d.qr, d.dqr, d.ddqr, o);
    benchmark::DoNotOptimize(p.processed.record.tau.data());
  }
}
BENCHMARK(given_orders)->Unit(benchmark::kMillisecond)->Iterations(1);

void chosen_orders(benchmark::State& state) {
  const Data d = make_data(100000, 6);
  for (auto _ : state) {
    auto p = dynid::project_on_reference(d.run, d.qr, d.dqr, d.ddqr);
    state.counters["M"] = p.m1;
    benchmark::DoNotOptimize(p.processed.record.tau.data());
  }
}
BENCHMARK(chosen_orders)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
