// Period averaging (seed 2 §3.4) and period detection on synthetic periodic data + noise.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "dynid/common/error.hpp"
#include "dynid/signal/period_averaging.hpp"
#include "support/error_of.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

using testing::expect_message;

// Hand-computed oracle: 3 periods of 2 samples, one channel, plus a trailing partial period.
TEST(AveragePeriods, SmallCaseByHand) {
  Eigen::MatrixXd x(7, 1);
  x << 1, 10, 2, 14, 6, 12, 99;
  const PeriodAverage a = average_periods(x, 2);
  EXPECT_EQ(a.periods, 3);
  EXPECT_EQ(a.unused_samples, 1);
  EXPECT_DOUBLE_EQ(a.mean(0, 0), 3.0);      // (1+2+6)/3
  EXPECT_DOUBLE_EQ(a.mean(1, 0), 12.0);     // (10+14+12)/3
  EXPECT_DOUBLE_EQ(a.variance(0, 0), 7.0);  // (4+1+9)/2
  EXPECT_DOUBLE_EQ(a.variance(1, 0), 4.0);  // (4+4+0)/2
  EXPECT_DOUBLE_EQ(a.channel_variance(0), 5.5);
  PeriodAverageOptions skip;
  skip.skip_periods = 1;
  const PeriodAverage b = average_periods(x, 2, skip);
  EXPECT_EQ(b.periods, 2);
  EXPECT_DOUBLE_EQ(b.mean(0, 0), 4.0);
  EXPECT_DOUBLE_EQ(b.variance(1, 0), 2.0);  // (14−13)² + (12−13)²
}

// 25 periods (as in seed 2) of a two-channel Fourier signal + Gaussian noise, σ = (0.05, 0.2).
// Mean: each x̄_k − s_k ~ N(0, σ²/25); over 2·300 samples, |error| < 5σ/5 fails with prob ≈ 3e−4.
// Pooled variance: P(K−1) = 7200 degrees of freedom → relative std sqrt(2/7200) = 1.7 %; 5σ = 8.3
// %. Per-sample variances: (K−1)s²/σ² ~ χ²₂₄; their average over k is the pooled value (checked
// above); check also that the per-sample values scatter with the χ² relative spread sqrt(2/24) ≈
// 0.29.
// That RMS spread, estimated from P = 300 samples, has ≈ 4.6 % relative std (χ²₂₄ fourth
// moment 12(ν+4)/ν³), so ±25 % is > 5 std.
TEST(AveragePeriods, RecoversMeanAndNoiseVariance) {
  const int p = 300, k = 25;
  const double sigma[2] = {0.05, 0.2};
  std::mt19937 gen(2024);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd truth(p, 2), x(p * k, 2);
  for (int s = 0; s < p; ++s) {
    const double ph = 2 * kPi * s / p;
    truth(s, 0) = 0.8 * std::sin(ph) - 0.3 * std::cos(3 * ph) + 0.1;
    truth(s, 1) = 5.0 + 2.0 * std::sin(2 * ph + 0.4);
  }
  for (int i = 0; i < k; ++i)
    for (int s = 0; s < p; ++s)
      for (int c = 0; c < 2; ++c) x(i * p + s, c) = truth(s, c) + sigma[c] * normal(gen);
  const PeriodAverage a = average_periods(x, p);
  ASSERT_EQ(a.periods, k);
  EXPECT_EQ(a.unused_samples, 0);
  for (int c = 0; c < 2; ++c) {
    EXPECT_LT((a.mean.col(c) - truth.col(c)).cwiseAbs().maxCoeff(), 5.0 * sigma[c] / std::sqrt(k));
    const double s2 = sigma[c] * sigma[c];
    EXPECT_NEAR(a.channel_variance(c), s2, 5.0 * std::sqrt(2.0 / (p * (k - 1))) * s2);
    const double spread = std::sqrt((a.variance.col(c).array() - s2).square().mean()) / s2;
    EXPECT_NEAR(spread, std::sqrt(2.0 / (k - 1)), 0.25 * std::sqrt(2.0 / (k - 1)));
  }
}

TEST(DetectPeriod, FindsFundamentalNotMultiple) {
  const int p = 137;
  std::mt19937 gen(8);
  std::normal_distribution<double> normal(0.0, 0.05);
  Eigen::VectorXd y(p * 12 + 50);
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    const double ph = 2 * kPi * static_cast<double>(i % p) / p;
    y(i) = std::sin(ph) + 0.5 * std::sin(3 * ph + 1.0) + normal(gen);
  }
  EXPECT_EQ(detect_period(y), p);
  PeriodDetectionOptions o;
  o.min_period = 100;
  o.max_period = 400;
  EXPECT_EQ(detect_period(y, o), p);
  // A harmonic-rich but exact periodic signal: r(P) = 1 exactly.
  Eigen::VectorXd z(1000);
  for (Eigen::Index i = 0; i < z.size(); ++i) z(i) = static_cast<double>((i % 40) < 10);
  EXPECT_EQ(detect_period(z), 40);
}

// check_period_repeats: 6 periods of 1 s at 100 Hz of a noise-free reference qr1 and a measured
// q1 = qr1 + N(0, 0.01²). The right period passes silently; a wrong one is an error naming qr1
// and the period its autocorrelation shows; without the reference, a wrong period is a warning on
// q1 (its spread is the signal's own variation, not noise).
TEST(CheckPeriodRepeats, RightPeriodPassesWrongOneIsNamed) {
  const int m = 600;
  Eigen::VectorXd t(m);
  Eigen::MatrixXd x(m, 2);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 0.01);
  for (int k = 0; k < m; ++k) {
    t[k] = k * 0.01;
    x(k, 0) = std::sin(2 * kPi * t[k]) + 0.3 * std::cos(6 * kPi * t[k]);
    x(k, 1) = x(k, 0) + g(rng);
  }
  const std::vector<std::string> names = {"qr1", "q1"};
  EXPECT_TRUE(check_period_repeats(average_periods_in_time(t, x, 1.0), x, names).empty());
  const TimedPeriodAverage wrong = average_periods_in_time(t, x, 0.7);
  const std::string e = testing::error_of([&] { check_period_repeats(wrong, x, names); });
  EXPECT_EQ(e.rfind("the reference qr1 does not repeat with the period 0.7 s", 0), 0u) << e;
  EXPECT_NE(e.find("its own period is 1 s"), std::string::npos) << e;
  const TimedPeriodAverage wrong_q = average_periods_in_time(t, x.rightCols(1), 0.7);
  const auto w = check_period_repeats(wrong_q, x.rightCols(1), {"q1"});
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].rfind("q1 spreads by", 0), 0u) << w[0];
  EXPECT_TRUE(is_reference_channel("ddqr12"));
  EXPECT_FALSE(is_reference_channel("qr"));
  EXPECT_FALSE(is_reference_channel("q1"));
}

// A held joint (examples/comau-s2's one-joint runs: q1 held while another joint follows its
// reference) has a range that is its noise: its spread across periods is then ~15 % of that range
// whatever the period, and said nothing about the period ("q1 spreads by 10.9 % of its range").
// It passes silently; the same joint drifting by 30 σ over the run, or the moving joint averaged
// with a wrong period, still warns.
TEST(CheckPeriodRepeats, AHeldJointsNoiseIsNotASpreadButItsDriftIs) {
  const int m = 3000;  // 6 periods of 1 s at 500 Hz
  Eigen::VectorXd t(m);
  Eigen::MatrixXd x(m, 3);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1e-4);
  for (int k = 0; k < m; ++k) {
    t[k] = k / 500.0;
    x(k, 0) = 0.2 + g(rng);                                    // q1 held
    x(k, 1) = 0.8 * std::sin(2 * kPi * t[k]) + 1e-4 * g(rng);  // q2 moving
    x(k, 2) = 0.2 + 3e-3 * k / (m - 1.0) + g(rng);             // q3 held, drifting by 30 σ
  }
  const std::vector<std::string> names = {"q1", "q2", "q3"};
  const TimedPeriodAverage right = average_periods_in_time(t, x, 1.0);
  // The case: the held joint spreads by more than 10 % of its range.
  const auto held = x.col(0);
  EXPECT_GT(right.channels[0].std / (held.maxCoeff() - held.minCoeff()), 0.1);
  const auto w = check_period_repeats(right, x, names);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_EQ(w[0].rfind("q3 spreads by", 0), 0u) << w[0];
  // Encoder counts of 2.4e-5 rad (2^18 per revolution) on a held joint with 2e-5 rad of noise:
  // its samples wander over a few counts.
  Eigen::MatrixXd counts = x.leftCols(2);
  const double step = 2 * kPi / 262144;
  for (int k = 0; k < m; ++k) counts(k, 0) = step * std::round(x(k, 0) * 2e-1 / step);
  EXPECT_TRUE(
      check_period_repeats(average_periods_in_time(t, counts, 1.0), counts, {"q1", "q2"}).empty());
  const auto wrong = check_period_repeats(average_periods_in_time(t, x.leftCols(2), 0.7),
                                          x.leftCols(2), {"q1", "q2"});
  ASSERT_EQ(wrong.size(), 1u);
  EXPECT_EQ(wrong[0].rfind("q2 spreads by", 0), 0u) << wrong[0];
}

TEST(PeriodErrors, Messages) {
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(10, 2);
  expect_message([&] { average_periods(x, 0); },
                 "period is 0 samples: give the period of the experiment in samples (>= 1)");
  PeriodAverageOptions o;
  o.skip_periods = -1;
  expect_message([&] { average_periods(x, 2, o); },
                 "skip_periods is -1: give a non-negative number of leading periods to drop");
  o.skip_periods = 1;
  expect_message([&] { average_periods(x, 4, o); },
                 "period averaging needs at least 2 complete periods of 4 samples after skipping "
                 "1 periods, i.e. 12 samples, but got 10: record more periods or check the period");
  const Eigen::VectorXd y = Eigen::VectorXd::LinSpaced(100, 0.0, 1.0);
  PeriodDetectionOptions d;
  d.max_period = 60;
  expect_message([&] { detect_period(y, d); },
                 "period search range [2, 60] samples does not fit two periods into the 100 "
                 "samples given: use 1 <= min_period <= max_period <= 50");
  expect_message([&] { detect_period(Eigen::VectorXd::Constant(100, 3.0)); },
                 "period detection reference signal is constant or contains NaN/Inf: give the "
                 "commanded trajectory of a moving joint");
  // A ramp has no interior autocorrelation peak (r(L) decreases with L).
  expect_message([&] { detect_period(y); },
                 "no autocorrelation peak found between 2 and 50 samples: widen the period range "
                 "or give the period explicitly");
}

}  // namespace
}  // namespace dynid
