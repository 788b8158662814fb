// Error statistics against known distributions and hand-computed moments; validation by
// simulation separates a correct model from a wrong one.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/sim/simulation_validation.hpp"
#include "sim/sim_support.hpp"
#include "support/planar2.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

// e = (1, 2, 3, 4, 10): μ = 4, deviations (−3, −2, −1, 0, 6), m2 = 10, m3 = 36, m4 = 278.8, so
// σ = √10, skewness = 36/10^1.5, kurtosis = 2.788, rms = √(130/5), max = 10 (by hand).
TEST(ErrorStatistics, MomentsMatchHandComputation) {
  Eigen::VectorXd e(5);
  e << 1, 2, 3, 4, 10;
  const ErrorStatistics s = error_statistics(e);
  EXPECT_EQ(s.samples, 5);
  EXPECT_NEAR(s.mean, 4.0, 1e-14);
  EXPECT_NEAR(s.std, std::sqrt(10.0), 1e-14);
  EXPECT_NEAR(s.skewness, 36.0 / std::pow(10.0, 1.5), 1e-14);
  EXPECT_NEAR(s.kurtosis, 2.788, 1e-13);
  EXPECT_NEAR(s.rms, std::sqrt(26.0), 1e-14);
  EXPECT_EQ(s.max_abs, 10.0);
}

// Tabulated Kolmogorov distribution: Q(1.36) = 0.0494, Q(1.63) = 0.0098 (the 5 % and 1 % critical
// values), Q(0.5) = 0.9639; both series agree where they meet.
TEST(ErrorStatistics, KolmogorovSurvivalMatchesTable) {
  EXPECT_NEAR(kolmogorov_survival(1.36), 0.0494, 1e-4);
  EXPECT_NEAR(kolmogorov_survival(1.63), 0.0098, 1e-4);
  EXPECT_NEAR(kolmogorov_survival(0.5), 0.9639, 1e-4);
  EXPECT_NEAR(kolmogorov_survival(1.0 - 1e-12), kolmogorov_survival(1.0), 1e-10);
  EXPECT_EQ(kolmogorov_survival(0.0), 1.0);
}

// Gaussian draws: skewness within 5√(6/N), kurtosis within 5√(24/N) of 3, KS D below the 1 %
// critical value 1.63/√N. Uniform draws: D equals sup|Φ(x/σ) − F_U(x)| (computed here on a fine
// grid) within 1.63/√N, and the p-value rejects.
TEST(ErrorStatistics, DistinguishesGaussianFromUniform) {
  const int n = 20000;
  std::mt19937_64 rng(123);
  std::normal_distribution<double> normal(0.5, 2.0);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd g(n), u(n);
  for (int i = 0; i < n; ++i) g[i] = normal(rng);
  for (int i = 0; i < n; ++i) u[i] = uniform(rng);
  const ErrorStatistics sg = error_statistics(g), su = error_statistics(u);
  EXPECT_NEAR(sg.mean, 0.5, 5 * 2.0 / std::sqrt(n));
  EXPECT_NEAR(sg.std, 2.0, 5 * 2.0 / std::sqrt(2.0 * n));
  EXPECT_NEAR(sg.skewness, 0.0, 5 * std::sqrt(6.0 / n));
  EXPECT_NEAR(sg.kurtosis, 3.0, 5 * std::sqrt(24.0 / n));
  EXPECT_LT(sg.ks_statistic, 1.63 / std::sqrt(n));
  EXPECT_GT(sg.ks_p_value, 0.01);
  // Uniform on [−1, 1]: σ = 1/√3, kurtosis 1.8.
  const double sigma = 1.0 / std::sqrt(3.0);
  double d = 0.0;
  for (double x = -1.0; x <= 1.0; x += 1e-5)
    d = std::max(d, std::abs(0.5 * std::erfc(-x / (sigma * std::sqrt(2.0))) - 0.5 * (x + 1.0)));
  d = std::max(d, 0.5 * std::erfc(1.0 / (sigma * std::sqrt(2.0))));  // tails beyond ±1
  EXPECT_NEAR(su.kurtosis, 1.8, 5 * std::sqrt(24.0 / n));
  EXPECT_NEAR(su.ks_statistic, d, 1.63 / std::sqrt(n));
  EXPECT_LT(su.ks_p_value, 1e-6);
}

// Uniform on [−1, 1] has density 1/2: with 20 bins over its range, each bin holds ~1000 of 20000
// samples (binomial σ ≈ 31, i.e. 3 % of the density); the density integrates to 1 by construction
// and the Gaussian column is N(μ, σ²) of the sample at the centres.
TEST(ErrorHistogram, UniformDensityAndGaussianBeside) {
  const int n = 20000;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::VectorXd u(n);
  for (int i = 0; i < n; ++i) u[i] = uniform(rng);
  const ErrorHistogram h = error_histogram(u, 20);
  ASSERT_EQ(h.center.size(), 20);
  const double width = h.center[1] - h.center[0];
  EXPECT_NEAR(h.density.sum() * width, 1.0, 1e-12);
  for (int b = 0; b < 20; ++b) EXPECT_NEAR(h.density[b], 0.5, 5 * 0.5 * 31.0 / 1000.0) << b;
  const ErrorStatistics s = error_statistics(u);
  const double z = (h.center[3] - s.mean) / s.std;
  EXPECT_NEAR(h.gaussian[3], std::exp(-0.5 * z * z) / (s.std * std::sqrt(2 * kPi)), 1e-12);
  EXPECT_THROW(error_histogram(u, 0), Error);
  const ErrorHistogram c = error_histogram(Eigen::VectorXd::Constant(4, 2.0), 3);
  EXPECT_NEAR(c.density.sum() * (c.center[1] - c.center[0]), 1.0, 1e-12);
  EXPECT_EQ(c.gaussian.sum(), 0.0);
}

TEST(ErrorStatistics, RejectsBadInput) {
  EXPECT_THROW(error_statistics(Eigen::VectorXd::Zero(1)), Error);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(5);
  e[2] = NAN;
  EXPECT_THROW(error_statistics(e), Error);
  const ErrorStatistics c = error_statistics(Eigen::VectorXd::Constant(4, 2.0));
  EXPECT_EQ(c.std, 0.0);
  EXPECT_EQ(c.ks_p_value, 0.0);
}

// A "measured" run from the MuJoCo plant with encoder, position and torque noise, validated with
// the true model and with a model whose masses are 30 % off. With the true model the position
// error is the sensor noise (std within 10 % of σ_q = 1e-4; the quantisation 2π/2¹⁸ adds 7e-6 in
// quadrature, 0.25 %) and
// is Gaussian (|skew| < 0.1, |kurtosis − 3| < 0.3); the wrong model's torque error is larger.
TEST(SimulationValidation, SeparatesTrueModelFromWrongModel) {
  const testing::Planar2 arm;
  const Model truth = arm.model();
  const double ts = 1e-3;
  const Reference ref = testing::sine_reference(
      Eigen::Vector2d(0.6, 0.8), Eigen::Vector2d(-1.2, 0.4), 2 * kPi * 0.5, ts, 2000);
  PidOptions po;
  po.kp = Eigen::Vector2d(300.0, 200.0);
  po.ki = Eigen::Vector2d(100.0, 100.0);
  po.kd = Eigen::Vector2d(30.0, 20.0);
  po.derivative_filter_time = 5e-3;
  po.feed_forward = FeedForward::kComputedTorque;
  PlantOptions mj;
  mj.engine = PlantEngine::kMujoco;
  auto plant = make_plant(truth, mj);
  PidController pid(truth, po);
  SensorOptions so;
  so.counts_per_rev = 1 << 18;
  so.position_noise_std = 1e-4;
  so.torque_noise_std = 0.05;
  so.seed = 9;
  Sensors sensors(truth, so);
  ClosedLoopOptions lo;
  lo.periods = 3;
  const ClosedLoopResult measured = run_closed_loop(ref, pid, *plant, sensors, lo);

  SimulationValidationOptions vo;
  vo.skip_samples = 500;
  const SimulationValidation good =
      validate_by_simulation(truth, ref, po, measured.q, measured.tau, vo);
  Model wrong = truth;
  for (auto& l : wrong.links) l *= 1.3;
  const SimulationValidation bad =
      validate_by_simulation(wrong, ref, po, measured.q, measured.tau, vo);
  ASSERT_EQ(good.position.size(), 2u);
  for (int j = 0; j < 2; ++j) {
    EXPECT_EQ(good.position[j].samples, 5500);
    EXPECT_NEAR(good.position[j].std, 1e-4, 1e-5);
    EXPECT_NEAR(good.position[j].skewness, 0.0, 0.1);
    EXPECT_NEAR(good.position[j].kurtosis, 3.0, 0.3);
    EXPECT_LT(3 * good.torque[j].rms, bad.torque[j].rms);
  }
}

TEST(SimulationValidation, RejectsMismatchedData) {
  const testing::Planar2 arm;
  const Model model = arm.model();
  const Reference ref = testing::sine_reference(Eigen::Vector2d(0.6, 0.8), Eigen::Vector2d::Zero(),
                                                2 * kPi, 1e-3, 1000);
  PidOptions po;
  po.kp = Eigen::Vector2d(100.0, 100.0);
  EXPECT_THROW(validate_by_simulation(model, ref, po, Eigen::MatrixXd::Zero(10, 3),
                                      Eigen::MatrixXd::Zero(10, 3)),
               Error);
  SimulationValidationOptions vo;
  vo.skip_samples = 9;
  EXPECT_THROW(validate_by_simulation(model, ref, po, Eigen::MatrixXd::Zero(10, 2),
                                      Eigen::MatrixXd::Zero(10, 2), vo),
               Error);
}

}  // namespace
}  // namespace dynid
