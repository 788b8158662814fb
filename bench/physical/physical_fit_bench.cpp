// The physically consistent fit (`dynid identify --physical`, log-Cholesky + Ceres) on its own,
// after the identification it starts from (issue 15 item 7, aim ≤ 1 s each): the real Stäubli
// TX40 run (examples/staubli-tx40/dataset, SOURCE.md; skipped when absent) and the 7-DoF iiwa14
// on a simulated multi-sine run (rnea + noise, 20 s at 200 Hz, every parameter excited).
// Run: ./build/bench/physical_fit_bench
#include <filesystem>
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/physical/physical_parameters.hpp"

namespace {

struct FitInput {
  dynid::Model model;
  dynid::IdentificationResult result;
};

void run_fit(benchmark::State& st, const FitInput& in) {
  const dynid::ParameterLayout layout = dynid::IdentifyOptions{}.layout;
  dynid::PhysicalFit fit;
  for (auto _ : st) {
    fit = dynid::physical_parameters(in.model, in.result.base, layout, in.result.estimate.x,
                                     in.result.estimate.covariance);
    benchmark::DoNotOptimize(fit.theta.data());
  }
  st.counters["iterations_lm"] = fit.iterations;
  st.counters["sigma"] = fit.mahalanobis;
  st.counters["sigma_limit"] = fit.chi2_limit;
  st.counters["rank"] = in.result.rank;
  st.counters["nominal_distance"] = fit.nominal_distance;
}

void BM_PhysicalFitTx40(benchmark::State& st) {
  // The examples folder of the source tree, from the built-in robots' folder (examples/robots).
  const std::string example = dynid::builtin_robots_dir() + "/../staubli-tx40";
  const std::string data = example + "/dataset";
  if (!std::filesystem::exists(data + "/data/pos_read_data.csv")) {
    st.SkipWithError("no TX40 data set in examples/staubli-tx40/dataset");
    return;
  }
  static const FitInput in = [&] {
    dynid::Model model = dynid::load_robot(example + "/tx40.yaml");
    const dynid::CsvTable pos = dynid::read_csv(data + "/data/pos_read_data.csv");
    const dynid::CsvTable cur = dynid::read_csv(data + "/data/curr_data.csv");
    const double ts = 2e-4;  // config/T40X_config.yaml `ts` (SOURCE.md: 5 kHz)
    dynid::JointRecord r;
    r.t = Eigen::VectorXd::LinSpaced(pos.rows(), 0.0, (pos.rows() - 1) * ts);
    r.q = dynid::joint_positions_from_motor(model, pos.data);
    r.tau = dynid::joint_torques_from_motor(model, cur.data);
    dynid::IdentificationResult result = dynid::identify(model, r);
    return FitInput{std::move(model), std::move(result)};
  }();
  run_fit(st, in);
}

void BM_PhysicalFitIiwa14(benchmark::State& st) {
  static const FitInput in = [] {
    dynid::Model model = dynid::load_robot("iiwa14");
    const int n = model.dof();
    const double rate = 200.0;
    const int m = 4000;
    dynid::JointRecord r;
    r.t = Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) / rate);
    r.q.resize(m, n);
    r.dq.resize(m, n);
    r.ddq.resize(m, n);
    r.tau.resize(m, n);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 0.1);
    dynid::Workspace ws(model);
    Eigen::VectorXd q(n), dq(n), ddq(n), tau(n);
    for (int k = 0; k < m; ++k) {
      const double t = r.t[k];
      for (int j = 0; j < n; ++j) {
        q[j] = dq[j] = ddq[j] = 0.0;
        for (int h = 1; h <= 3; ++h) {
          // Distinct incommensurate frequencies per joint and harmonic: every column excited.
          const double w = 2.0 * M_PI * (0.1 + 0.037 * j) * (1.0 + 1.3 * h);
          const double a = 0.5 / h;
          q[j] += a * std::sin(w * t + j + h);
          dq[j] += a * w * std::cos(w * t + j + h);
          ddq[j] -= a * w * w * std::sin(w * t + j + h);
        }
      }
      dynid::rnea(model, ws, q, dq, ddq, tau);
      for (int j = 0; j < n; ++j) tau[j] += noise(rng);
      r.q.row(k) = q.transpose();
      r.dq.row(k) = dq.transpose();
      r.ddq.row(k) = ddq.transpose();
      r.tau.row(k) = tau.transpose();
    }
    dynid::IdentifyOptions o;
    o.signal.filter = false;
    dynid::IdentificationResult result = dynid::identify(model, r, o);
    return FitInput{std::move(model), std::move(result)};
  }();
  run_fit(st, in);
}

}  // namespace

BENCHMARK(BM_PhysicalFitTx40)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_PhysicalFitIiwa14)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_MAIN();
