// Differentiation on non-uniform time: exactness on polynomials (closed-form derivatives),
// convergence on a sine, and every error message.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "dynid/common/error.hpp"
#include "dynid/signal/differentiation.hpp"
#include "dynid/signal/sample_selection.hpp"
#include "dynid/signal/sampling_check.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

// Strictly increasing, clearly non-uniform time: steps uniform in [0.5, 1.5]·h (fixed seed).
Eigen::VectorXd jittered_time(int m, double h, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  Eigen::VectorXd t(m);
  t(0) = 0.3;
  for (int k = 1; k < m; ++k) t(k) = t(k - 1) + h * u(gen);
  return t;
}

// Polynomial p(t) = Σ c_i t^i and its derivatives, in closed form (the oracle).
double poly(const Eigen::VectorXd& c, double t, int deriv) {
  double s = 0.0;
  for (int i = deriv; i < c.size(); ++i) {
    double f = 1.0;
    for (int j = 0; j < deriv; ++j) f *= (i - j);
    s += c(i) * f * std::pow(t, i - deriv);
  }
  return s;
}

Eigen::MatrixXd sample(const Eigen::VectorXd& t, const Eigen::MatrixXd& coeffs, int deriv) {
  Eigen::MatrixXd x(t.size(), coeffs.cols());
  for (Eigen::Index k = 0; k < t.size(); ++k)
    for (Eigen::Index j = 0; j < coeffs.cols(); ++j) x(k, j) = poly(coeffs.col(j), t(k), deriv);
  return x;
}

TEST(CentralDifference, ExactForQuadraticsOnNonUniformTime) {
  const Eigen::VectorXd t = jittered_time(60, 0.01, 7);
  Eigen::MatrixXd c(3, 2);
  c << 0.4, -2.0, 1.5, 0.7, -3.0, 12.0;  // two quadratics, one per column
  const Eigen::MatrixXd x = sample(t, c, 0);
  const Eigen::MatrixXd v = central_difference(t, x, 1);
  const Eigen::MatrixXd a = central_difference(t, x, 2);
  EXPECT_LT((v - sample(t, c, 1)).cwiseAbs().maxCoeff(), 1e-9);  // includes both ends
  EXPECT_LT((a - sample(t, c, 2)).cwiseAbs().maxCoeff(), 1e-6);
}

TEST(CentralDifference, SecondOrderConvergenceOnSine) {
  // Error of the centred 3-point derivative on a smooth signal falls ≈ 4× when h halves
  // (uniform grid: error = h²/6·x'''); checked away from the ends.
  double previous = 0.0;
  for (int level = 0; level < 3; ++level) {
    const int m = 201 * (1 << level);
    const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, 1.0);
    const Eigen::VectorXd x = (6.0 * t.array()).sin();
    const Eigen::VectorXd v = central_difference(t, x).col(0);
    const Eigen::VectorXd exact = 6.0 * (6.0 * t.array()).cos();
    const double err = (v - exact).segment(m / 4, m / 2).cwiseAbs().maxCoeff();
    const double h = 1.0 / (m - 1);
    EXPECT_LE(err, h * h / 6.0 * 216.0 * 1.0001);
    if (level > 0) {
      EXPECT_NEAR(previous / err, 4.0, 0.1);
    }
    previous = err;
  }
}

TEST(SavitzkyGolay, ExactUpToItsOrderOnNonUniformTime) {
  const Eigen::VectorXd t = jittered_time(80, 0.002, 11);
  for (int order : {2, 3, 4}) {
    Eigen::MatrixXd c = Eigen::MatrixXd::Zero(order + 1, 2);
    for (int i = 0; i <= order; ++i) {
      c(i, 0) = 1.0 + 0.5 * i;
      c(i, 1) = (i % 2 ? -2.0 : 3.0) * std::pow(10.0, i);
    }
    const Eigen::MatrixXd x = sample(t, c, 0);
    for (int d = 0; d <= 2; ++d) {
      SavitzkyGolayOptions o;
      o.window = 9;
      o.order = order;
      o.derivative = d;
      const Eigen::MatrixXd y = savitzky_golay(t, x, o);
      const Eigen::MatrixXd exact = sample(t, c, d);
      const double rel = (y - exact).cwiseAbs().maxCoeff() / exact.cwiseAbs().maxCoeff();
      EXPECT_LT(rel, 1e-8) << "order " << order << " derivative " << d;
    }
  }
}

TEST(SavitzkyGolay, SmoothsNoiseAndDifferentiatesSine) {
  // On a sine, SG(window 21, order 4) first derivative has a small bias (truncation of the Taylor
  // series at degree 4 over ±10 steps) and averages white noise: its RMS error must be well below
  // that of the noisy 3-point difference on the same data.
  const int m = 2000;
  const Eigen::VectorXd t = jittered_time(m, 1e-3, 3);
  std::mt19937 gen(5);
  std::normal_distribution<double> noise(0.0, 1e-4);
  Eigen::VectorXd x(m), exact(m);
  for (int k = 0; k < m; ++k) {
    x(k) = std::sin(5.0 * t(k)) + noise(gen);
    exact(k) = 5.0 * std::cos(5.0 * t(k));
  }
  SavitzkyGolayOptions o;
  o.window = 21;
  o.order = 4;
  const double sg_rms = std::sqrt(
      (savitzky_golay(t, x, o).col(0) - exact).segment(20, m - 40).squaredNorm() / (m - 40));
  const double cd_rms = std::sqrt(
      (central_difference(t, x).col(0) - exact).segment(20, m - 40).squaredNorm() / (m - 40));
  EXPECT_LT(sg_rms, 0.1 * cd_rms);
}

using testing::expect_message;

TEST(SamplingCheck, UniformJitteredAndErrors) {
  const Eigen::VectorXd tu = Eigen::VectorXd::LinSpaced(101, 0.0, 0.1);
  const SamplingInfo u = check_sampling(tu);
  EXPECT_NEAR(u.mean_period, 1e-3, 1e-15);
  EXPECT_NEAR(u.rate_hz(), 1000.0, 1e-9);
  EXPECT_LT(u.max_relative_deviation, 1e-9);
  EXPECT_TRUE(u.uniform);
  Eigen::VectorXd tj = tu;
  tj(50) += 2e-4;  // steps 1.2 ms and 0.8 ms: 20 % deviation
  const SamplingInfo j = check_sampling(tj);
  EXPECT_NEAR(j.max_relative_deviation, 0.2, 1e-9);
  EXPECT_FALSE(j.uniform);
  EXPECT_TRUE(check_sampling(tj, 0.25).uniform);

  Eigen::VectorXd bad = tu;
  bad(7) = bad(6);
  expect_message([&] { check_sampling(bad); },
                 "time is not strictly increasing at row 7 (0-based): t[7] = 0.0060000000000000001 "
                 "<= t[6] = 0.0060000000000000001; sort the samples and remove duplicates");
  bad = tu;
  bad(3) = std::nan("");
  expect_message([&] { check_sampling(bad); },
                 "time t[3] is NaN or Inf: fix or drop that sample (row 3, 0-based)");
  expect_message([&] { check_sampling(Eigen::VectorXd::Zero(1)); },
                 "time vector has 1 samples: give at least 2 time stamps");
  expect_message([&] { require_uniform_sampling(tj, 1e-3, "decimation"); },
                 "decimation needs uniform sampling but the time steps deviate up to 20 % from "
                 "the mean period 0.001 s (tolerance 0.1 %): resample onto a uniform grid first "
                 "(resample_uniform)");
}

TEST(DifferentiationErrors, Messages) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(20, 0.0, 1.0);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Zero(20, 2);
  expect_message([&] { central_difference(t, x, 3); },
                 "central difference derivative is 3: give 1 (velocity) or 2 (acceleration)");
  expect_message([&] { central_difference(t.head(19), x); },
                 "central difference: time vector has 19 samples but the data has 20 rows: give "
                 "one time stamp per row");
  expect_message([&] { central_difference(t.head(2), x.topRows(2)); },
                 "central difference needs at least 3 samples, got 2: give a longer record");
  Eigen::VectorXd tb = t;
  tb(4) = 0.0;
  expect_message([&] { central_difference(tb, x); },
                 "time is not strictly increasing at row 4 (0-based): t[4] = 0 <= t[3] = "
                 "0.15789473684210525; sort the samples and remove duplicates");
  SavitzkyGolayOptions o;
  o.window = 10;
  expect_message([&] { savitzky_golay(t, x, o); },
                 "Savitzky-Golay window is 10 samples: give an odd window (e.g. 11)");
  o.window = 5;
  o.order = 5;
  expect_message([&] { savitzky_golay(t, x, o); },
                 "Savitzky-Golay order 5 with window 5: give 0 <= order < window");
  o.order = 1;
  o.derivative = 2;
  expect_message([&] { savitzky_golay(t, x, o); },
                 "Savitzky-Golay derivative is 2: give 0, 1 or 2, at most the polynomial order 1");
  o.order = 3;
  o.window = 21;
  expect_message([&] { savitzky_golay(t, x, o); },
                 "Savitzky-Golay window of 21 samples exceeds the 20 samples given: shorten the "
                 "window or give more data");
  o.window = 5;
  expect_message([&] { savitzky_golay(t.head(19), x, o); },
                 "Savitzky-Golay: time vector has 19 samples but the data has 20 rows: give one "
                 "time stamp per row");
}

TEST(SampleSelection, TrimAndMovingMask) {
  Eigen::MatrixXd x(6, 2);
  x << 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11;
  const Eigen::MatrixXd y = trim_edges(x, 2, 1);
  ASSERT_EQ(y.rows(), 3);
  EXPECT_EQ(y(0, 0), 4.0);
  EXPECT_EQ(y(2, 1), 9.0);
  expect_message([&] { trim_edges(x, -1, 0); },
                 "trim counts are -1 and 0: give non-negative numbers of samples to drop");
  expect_message([&] { trim_edges(x, 3, 3); },
                 "trimming 3 + 3 samples leaves nothing of the 6 samples: trim less or give a "
                 "longer record");
  Eigen::MatrixXd dq(4, 2);
  dq << 0.0, -0.5, 0.02, 0.05, -0.2, 0.001, 0.05, -0.06;
  Eigen::Vector2d th(0.05, 0.06);
  const RowMask mask = moving_sample_mask(dq, th);
  RowMask expected(4, 2);
  expected << false, true, false, false, true, false, true, true;
  EXPECT_TRUE((mask == expected).all());
  const RowMask one = moving_sample_mask(dq, Eigen::VectorXd::Constant(1, 0.1));
  EXPECT_EQ(one.count(), 2);
  expect_message(
      [&] { moving_sample_mask(dq, Eigen::Vector3d(1, 1, 1)); },
      "velocity thresholds have 3 values for 2 joints: give one per joint or one for all");
  expect_message([&] { moving_sample_mask(dq, Eigen::Vector2d(0.1, -1.0)); },
                 "velocity threshold 1 is -1: give a non-negative speed below which samples are "
                 "dropped");
}

}  // namespace
}  // namespace dynid
