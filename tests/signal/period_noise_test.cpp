// Period averaging with a period in seconds and noise statistics (issue 13 item 4, seed 2 §3.4,
// Fig. 5). Oracles: a known periodic signal plus noise drawn here with fixed seeds (the std, the
// distribution's skewness and kurtosis known in closed form: Gaussian 0/3, uniform 0/1.8, centred
// exponential 2/9); the D'Agostino–Pearson test's calibration (its p-values under normality are
// uniform, so about 5 % of Gaussian samples fall below 0.05).
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "dynid/signal/period_averaging.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

constexpr double kTs = 0.005;  // 200 Hz

double signal(double t, double period, int channel) {
  const double w = 2 * M_PI / period;
  return channel == 0 ? 0.8 * std::sin(w * t) + 0.2 * std::cos(3 * w * t + 0.4)
                      : 5.0 * std::sin(2 * w * t + 1.0) - 2.0;
}

// Run of `samples` at kTs from t0: channel 0 with Gaussian noise σ0, channel 1 with noise drawn by
// `noise1` (zero mean), channel 2 the noise-free signal 0 (a reference).
template <class Noise>
void make_run(long samples, double t0, double period, double sigma0, Noise noise1,
              Eigen::VectorXd& t, Eigen::MatrixXd& x, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma0);
  t.resize(samples);
  x.resize(samples, 3);
  for (long s = 0; s < samples; ++s) {
    t[s] = t0 + s * kTs;
    x(s, 0) = signal(t[s], period, 0) + g(rng);
    x(s, 1) = signal(t[s], period, 1) + noise1(rng);
    x(s, 2) = signal(t[s], period, 0);
  }
}

TEST(PeriodNoise, NonIntegerPeriodDriftingStartPartialLastPeriodRecoverMeanAndNoise) {
  const double period = 1.2345;  // 246.9 samples: every period starts at another phase
  const double sigma0 = 1e-3, half_width = 0.02;  // uniform noise on ±0.02: σ = 0.02/√3
  std::uniform_real_distribution<double> u(-half_width, half_width);
  Eigen::VectorXd t;
  Eigen::MatrixXd x;
  const long samples = static_cast<long>(25.4 * period / kTs);  // 25 periods and 0.4 of one
  make_run(samples, 0.3, period, sigma0, u, t, x, 7);
  TimedPeriodAverageOptions o;
  o.start = 0.3 + 0.4 * kTs;  // the first period starts between samples
  const TimedPeriodAverage a = average_periods_in_time(t, x, period, o);
  EXPECT_EQ(a.periods, 25);
  EXPECT_TRUE(a.interpolated);
  EXPECT_NEAR(a.samples_per_period, period / kTs, 1e-9);
  EXPECT_EQ(a.mean.rows(), 247);
  EXPECT_EQ(a.samples_before, 1);
  EXPECT_NEAR(a.partial_period, (samples - (0.4 + 25 * period / kTs)) / (period / kTs), 1e-9);
  EXPECT_GT(a.samples_after, 0);
  // Mean period vs the signal at the phase times: within 4 standard errors of a 25-period mean
  // of interpolated noise (≤ σ/√25·1) plus the cubic interpolation error (< 1e-4 here).
  for (Eigen::Index q = 0; q < a.mean.rows(); ++q) {
    EXPECT_NEAR(a.mean(q, 0), signal(o.start + a.phase[q], period, 0), 4 * sigma0 / 5 + 1e-4);
    EXPECT_NEAR(a.mean(q, 2), signal(o.start + a.phase[q], period, 0), 1e-4);
  }
  // std within 4 sampling standard deviations: sd(σ̂)/σ = sqrt((kurtosis − 1)/(4n)).
  const double n = static_cast<double>(a.residual_samples);
  const double sigma1 = half_width / std::sqrt(3.0);
  EXPECT_NEAR(a.channels[0].std, sigma0, 4 * sigma0 * std::sqrt(2.0 / (4 * n)));
  EXPECT_NEAR(a.channels[1].std, sigma1, 4 * sigma1 * std::sqrt(0.8 / (4 * n)));
  EXPECT_NEAR(a.channels[0].kurtosis, 3.0, 0.15);
  EXPECT_NEAR(a.channels[1].kurtosis, 1.8, 0.1);
  EXPECT_NEAR(a.channels[1].skewness, 0.0, 0.1);
  EXPECT_GT(a.channels[0].normality_p, 0.01);  // Gaussian accepted
  EXPECT_LT(a.channels[1].normality_p, 1e-6);  // uniform rejected
  // The noise-free channel shows the cubic interpolation floor of this signal (measured 7.4e-8),
  // far below any encoder noise.
  EXPECT_LT(a.channels[2].std, 1e-6);
}

TEST(PeriodNoise, WholeSamplePeriodUsesTheSamplesAndHeavyTailsAreRejected) {
  const double period = 1.0;                             // 200 samples
  std::exponential_distribution<double> ex(1.0 / 0.01);  // σ = 0.01, skewness 2, kurtosis 9
  auto centred = [&](std::mt19937_64& r) { return ex(r) - 0.01; };
  Eigen::VectorXd t;
  Eigen::MatrixXd x;
  make_run(30 * 200, 0.0, period, 2e-3, centred, t, x, 11);
  const TimedPeriodAverage a = average_periods_in_time(t, x, period);
  EXPECT_FALSE(a.interpolated);
  EXPECT_EQ(a.periods, 30);
  EXPECT_EQ(a.samples_after, 0);
  EXPECT_EQ(a.partial_period, 0.0);
  EXPECT_EQ(a.channels[2].std, 0.0);  // exactly periodic samples: exactly zero residual
  const double n = static_cast<double>(a.residual_samples);
  EXPECT_NEAR(a.channels[0].std, 2e-3, 4 * 2e-3 * std::sqrt(2.0 / (4 * n)));
  EXPECT_NEAR(a.channels[1].std, 0.01, 4 * 0.01 * std::sqrt(8.0 / (4 * n)));
  EXPECT_NEAR(a.channels[1].skewness, 2.0, 0.3);
  EXPECT_NEAR(a.channels[1].kurtosis, 9.0, 2.0);
  EXPECT_LT(a.channels[1].normality_p, 1e-10);
}

TEST(PeriodNoise, NormalityTestIsCalibratedUnderTheNullAndRejectsHeavyTails) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  int below = 0;
  for (int r = 0; r < 400; ++r) {
    Eigen::VectorXd v(300);
    for (auto& e : v) e = g(rng);
    if (dagostino_pearson(v).p < 0.05) ++below;
  }
  // Binomial(400, 0.05): mean 20, sd 4.4.
  EXPECT_GE(below, 7);
  EXPECT_LE(below, 33);
  std::student_t_distribution<double> heavy(3.0);
  Eigen::VectorXd v(2000);
  for (auto& e : v) e = heavy(rng);
  EXPECT_LT(dagostino_pearson(v).p, 1e-6);
}

TEST(PeriodNoise, BadInputIsAClearError) {
  Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(300, 0.0, 299 * kTs);
  Eigen::MatrixXd x = Eigen::MatrixXd::Random(300, 2);
  EXPECT_EQ(testing::error_of([&] { average_periods_in_time(t, x, 1.0); }),
            "period 1 s gives 1 complete period(s) in the run of 1.5 s (300 samples from t = 0 "
            "s, skipping 0); averaging needs at least 2: check --period/--f0 or record more "
            "periods");
  EXPECT_NE(testing::error_of([&] {
              average_periods_in_time(t, x, 0.005);
            }).find("must be finite and at least two samples"),
            std::string::npos);
  TimedPeriodAverageOptions o;
  o.start = 5.0;
  EXPECT_NE(testing::error_of([&] {
              average_periods_in_time(t, x, 0.5, o);
            }).find("period start 5 s is outside the run"),
            std::string::npos);
  x(3, 1) = std::nan("");
  EXPECT_NE(testing::error_of([&] { average_periods_in_time(t, x, 0.5); }).find("NaN"),
            std::string::npos);
  EXPECT_NE(testing::error_of([&] {
              dagostino_pearson(Eigen::VectorXd::Ones(50));
            }).find("zero variance"),
            std::string::npos);
}

}  // namespace
}  // namespace dynid
