// Maximum likelihood with errors in variables (issue 13 item 7): the 6-joint PUMA 560 base set
// (armature and viscous friction), 2000 samples (10 s at 200 Hz) of a 4-harmonic Fourier
// trajectory, torques from the regressor at the true parameters plus white noise on q, q̇, q̈, τ;
// the solve from the OLS start (differential_sensitivity once, then Ceres), and the sensitivity
// alone.
// Run: ./build/bench/maximum_likelihood_bench --benchmark_repetitions=3
// --benchmark_report_aggregates_only=true
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/closed_loop/maximum_likelihood.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/robots.hpp"

namespace {

struct Problem {
  dynid::Model model;
  dynid::ParameterLayout layout;
  dynid::ProcessedRecord measured;
  dynid::BaseParameters base;
  dynid::EquationBlock block;
  dynid::MeasurementNoise noise;
};

Problem make_problem() {
  Problem p;
  p.model = dynid::load_robot("puma560");
  const int n = p.model.dof();
  p.layout.armature = true;
  p.layout.viscous = true;
  dynid::FourierCoefficients c = dynid::FourierCoefficients::zeros(std::vector<int>(n, 4), 0.1);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  for (int j = 0; j < n; ++j) {
    for (int h = 0; h < 4; ++h) {
      c.a[j][h] = u(rng);
      c.b[j][h] = u(rng);
    }
  }
  c.q0 = Eigen::VectorXd::Zero(n);
  const dynid::TrajectorySamples tr =
      dynid::sample_trajectory(dynid::FourierTrajectory(c), 200.0, false);
  const Eigen::Index m = 2000;
  p.measured.record.t = tr.t.head(m);
  p.measured.record.q = tr.q.topRows(m);
  p.measured.record.dq = tr.dq.topRows(m);
  p.measured.record.ddq = tr.ddq.topRows(m);
  dynid::BaseParameterOptions bo;
  bo.layout = p.layout;
  p.base = dynid::compute_base_parameters(p.model, bo);
  const Eigen::MatrixXd W = dynid::processed_regressor(p.model, p.layout, false, p.measured);
  const Eigen::VectorXd y = W * p.layout.parameters(p.model);
  p.noise.q = Eigen::VectorXd::Constant(n, 1e-3);
  p.noise.dq = Eigen::VectorXd::Constant(n, 1e-2);
  p.noise.ddq = Eigen::VectorXd::Constant(n, 0.2);
  p.noise.tau = Eigen::VectorXd::Constant(n, 0.05);
  std::normal_distribution<double> z;
  auto add = [&](Eigen::MatrixXd& x, const Eigen::VectorXd& s) {
    for (Eigen::Index k = 0; k < x.rows(); ++k)
      for (int j = 0; j < n; ++j) x(k, j) += s[j] * z(rng);
  };
  add(p.measured.record.q, p.noise.q);
  add(p.measured.record.dq, p.noise.dq);
  add(p.measured.record.ddq, p.noise.ddq);
  const Eigen::MatrixXd Wm = dynid::processed_regressor(p.model, p.layout, false, p.measured);
  p.block.W.resize(Wm.rows(), p.base.rank);
  for (int k = 0; k < p.base.rank; ++k) p.block.W.col(k) = Wm.col(p.base.base[k]);
  p.block.y = y;
  p.block.group.resize(y.size());
  p.block.sample.resize(y.size());
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    p.block.y[i] += p.noise.tau[i % n] * z(rng);
    p.block.group[i] = static_cast<int>(i % n);
    p.block.sample[i] = static_cast<int>(i / n);
  }
  return p;
}

void sensitivity(benchmark::State& state) {
  const Problem p = make_problem();
  for (auto _ : state) {
    const Eigen::MatrixXd s = dynid::differential_sensitivity(
        p.model, p.layout, false, p.measured, p.base.base, p.block.sample, p.block.group);
    benchmark::DoNotOptimize(s.data());
  }
  state.counters["base"] = p.base.rank;
}
BENCHMARK(sensitivity)->Unit(benchmark::kMillisecond)->Iterations(1);

void maximum_likelihood_solve(benchmark::State& state) {
  const Problem p = make_problem();
  for (auto _ : state) {
    const Eigen::MatrixXd s = dynid::differential_sensitivity(
        p.model, p.layout, false, p.measured, p.base.base, p.block.sample, p.block.group);
    const dynid::Estimate ols = dynid::ordinary_least_squares(p.block.W, p.block.y, p.block.group);
    dynid::MaximumLikelihoodSummary summary;
    const dynid::Estimate e =
        dynid::maximum_likelihood(p.block, s, p.noise, ols.x, {}, {}, &summary);
    benchmark::DoNotOptimize(e.x.data());
    state.counters["iterations"] = summary.iterations;
    state.counters["variance_factor"] = summary.variance_factor;
  }
  state.counters["base"] = p.base.rank;
}
BENCHMARK(maximum_likelihood_solve)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
