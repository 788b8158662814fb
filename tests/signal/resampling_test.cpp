// Interpolation, decimation and resampling: exactness on lines, spline error bound, alias removal.
#include <cmath>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "dynid/common/error.hpp"
#include "dynid/signal/resampling.hpp"
#include "support/error_of.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

Eigen::VectorXd jittered_time(int m, double h, unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(0.5, 1.5);
  Eigen::VectorXd t(m);
  t(0) = 0.0;
  for (int k = 1; k < m; ++k) t(k) = t(k - 1) + h * u(gen);
  return t;
}

// Amplitude of the component at frequency f [Hz] in y(t) by least squares on sin/cos (+ offset).
double amplitude(const Eigen::VectorXd& t, const Eigen::VectorXd& y, double f) {
  Eigen::MatrixXd phi(t.size(), 3);
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    phi(k, 0) = std::sin(2 * kPi * f * t(k));
    phi(k, 1) = std::cos(2 * kPi * f * t(k));
    phi(k, 2) = 1.0;
  }
  const Eigen::Vector3d c = phi.colPivHouseholderQr().solve(y);
  return c.head<2>().norm();
}

using testing::expect_message;

TEST(Interpolate, LinesExactKnotsExactSplineWithinBound) {
  const Eigen::VectorXd t = jittered_time(400, 1e-3, 21);
  Eigen::MatrixXd x(t.size(), 2);
  x.col(0) = 3.0 - 2.0 * t.array();
  x.col(1) = (2 * kPi * 7.0 * t.array()).sin();
  std::mt19937 gen(4);
  std::uniform_real_distribution<double> u(t(0), t(t.size() - 1));
  Eigen::VectorXd tq(300);
  for (Eigen::Index q = 0; q < tq.size(); ++q) tq(q) = u(gen);
  tq(0) = t(0);
  tq(1) = t(t.size() - 1);
  for (Interpolation method : {Interpolation::kLinear, Interpolation::kCubicSpline}) {
    const Eigen::MatrixXd y = interpolate(t, x, tq, method);
    EXPECT_LT((y.col(0) - (3.0 - 2.0 * tq.array()).matrix()).cwiseAbs().maxCoeff(), 1e-12);
    const Eigen::MatrixXd yk = interpolate(t, x, t, method);  // at the knots
    EXPECT_LT((yk - x).cwiseAbs().maxCoeff(), 1e-12);
  }
  // Spline error away from the (natural) ends: ≤ 5/384·h_max⁴·max|x⁗| (Hall & Meyer 1976).
  const Eigen::MatrixXd ys = interpolate(t, x, tq, Interpolation::kCubicSpline);
  double hmax = 0.0;
  for (Eigen::Index k = 1; k < t.size(); ++k) hmax = std::max(hmax, t(k) - t(k - 1));
  const double w = 2 * kPi * 7.0, bound = 5.0 / 384.0 * std::pow(hmax, 4) * std::pow(w, 4);
  double worst = 0.0;
  for (Eigen::Index q = 0; q < tq.size(); ++q) {
    if (tq(q) < t(30) || tq(q) > t(t.size() - 31)) continue;  // end effect decays as 0.27^k
    worst = std::max(worst, std::abs(ys(q, 1) - std::sin(w * tq(q))));
  }
  EXPECT_LE(worst, bound);
  EXPECT_GT(worst, 0.0);
}

TEST(Decimate, KeepsLowFrequencyKillsAboveNewNyquist) {
  // 1 kHz data, factor 10 → 100 Hz, new Nyquist 50 Hz, anti-alias cut-off 40 Hz.
  // 5 Hz must pass with the filtfilt passband gain, inside the Chebyshev ripple band
  // [10^(−2·0.05/20), 1]; 70 Hz (would alias to 30 Hz) must be attenuated at least to the analytic
  // |H(70 Hz)|² = 1/(1+ε²T_8²(tan(0.07π)/tan(0.04π))) ≈ 2.7e−6.
  const int m = 6000;
  Eigen::VectorXd t(m);
  Eigen::MatrixXd x(m, 2);
  for (int k = 0; k < m; ++k) {
    t(k) = 1e-3 * k;
    x(k, 0) = std::sin(2 * kPi * 5.0 * t(k)) + std::sin(2 * kPi * 70.0 * t(k));
    x(k, 1) = 0.5;
  }
  const UniformRecord d = decimate(t, x, 10);
  ASSERT_EQ(d.t.size(), 600);
  EXPECT_DOUBLE_EQ(d.t(1), t(10));
  const Eigen::VectorXd tm = d.t.segment(100, 400), ym = d.x.col(0).segment(100, 400);
  const double a5 = amplitude(tm, ym, 5.0);
  EXPECT_LE(a5, 1.0 + 1e-6);
  EXPECT_GE(a5, std::pow(10.0, -0.1 / 20.0) - 1e-6);
  const double eps2 = std::pow(10.0, 0.05 / 10.0) - 1.0;
  const double r = std::tan(0.07 * kPi) / std::tan(0.04 * kPi);
  const double t8 = std::cosh(8.0 * std::acosh(r));
  const double h2 = 1.0 / (1.0 + eps2 * t8 * t8);
  EXPECT_LT(amplitude(tm, ym, 30.0), 1.5 * h2);
  // Without the anti-alias filter the 70 Hz line folds onto 30 Hz at full amplitude.
  AntiAliasOptions off;
  off.enabled = false;
  const UniformRecord raw = decimate(t, x, 10, off);
  EXPECT_NEAR(amplitude(tm, raw.x.col(0).segment(100, 400), 30.0), 1.0, 1e-9);
  // Constant channel: DC gain of the even-order Chebyshev, 1/(1+ε²) after two passes.
  EXPECT_NEAR((d.x.col(1).array() - 0.5 / (1.0 + eps2)).abs().maxCoeff(), 0.0, 1e-12);
}

TEST(ResampleUniform, NonUniformDownsamplingRemovesAlias) {
  // ~1 kHz jittered data → 100 Hz: 3 Hz kept, 130 Hz (aliases to 30 Hz) removed.
  const Eigen::VectorXd t = jittered_time(8000, 1e-3, 9);
  Eigen::VectorXd x(t.size());
  for (Eigen::Index k = 0; k < t.size(); ++k)
    x(k) = std::sin(2 * kPi * 3.0 * t(k)) + std::sin(2 * kPi * 130.0 * t(k));
  const UniformRecord r = resample_uniform(t, x, 100.0);
  EXPECT_EQ(r.t.size(), static_cast<Eigen::Index>(std::floor(t(t.size() - 1) * 100.0)) + 1);
  EXPECT_NEAR(r.t(1) - r.t(0), 0.01, 1e-15);
  const Eigen::Index n = r.t.size();
  const Eigen::VectorXd tm = r.t.segment(100, n - 200), ym = r.x.col(0).segment(100, n - 200);
  // Passband: Chebyshev ripple 2·0.05 dB plus the spline error of a 3 Hz sine (≈ 1e−9).
  const double a3 = amplitude(tm, ym, 3.0);
  EXPECT_LE(a3, 1.0 + 1e-6);
  EXPECT_GE(a3, std::pow(10.0, -0.1 / 20.0) - 1e-6);
  // The 130 Hz line: stopband attenuation ≈ 1e−8 plus the spline error on the jittered grid, which
  // is ≤ 5/384·(1.5 ms)⁴·(2π·130)⁴ ≈ 0.04 before the filter and also filtered: require < 1e−3.
  EXPECT_LT(amplitude(tm, ym, 30.0), 1e-3);
  ResampleOptions off;
  off.anti_alias.enabled = false;
  const UniformRecord raw = resample_uniform(t, x, 100.0, off);
  EXPECT_GT(amplitude(tm, raw.x.col(0).segment(100, n - 200), 30.0), 0.9);
  // Upsampling a line with linear interpolation is exact and skips the filter.
  ResampleOptions lin;
  lin.interpolation = Interpolation::kLinear;
  const UniformRecord up = resample_uniform(t, (2.0 * t.array() + 1.0).matrix(), 4000.0, lin);
  EXPECT_LT((up.x.col(0) - (2.0 * up.t.array() + 1.0).matrix()).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(ResamplingErrors, Messages) {
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(100, 0.0, 0.099);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Zero(100, 1);
  expect_message([&] { decimate(t, x, 0); },
                 "decimation factor is 0: give an integer factor of at least 1");
  expect_message([&] { decimate(t.head(50), x, 2); },
                 "decimation: time vector has 50 samples but the data has 100 rows: give one time "
                 "stamp per row");
  Eigen::VectorXd tj = t;
  tj(10) += 5e-4;
  expect_message([&] { decimate(tj, x, 2); },
                 "decimation needs uniform sampling but the time steps deviate up to 50 % from the "
                 "mean period 0.001 s (tolerance 0.1 %): resample onto a uniform grid first "
                 "(resample_uniform)");
  expect_message([&] { decimate(t.head(20), x.topRows(20), 2); },
                 "zero-phase filter input has 20 samples but the order-8 filter pads 27 samples "
                 "per end: give at least 28 samples or lower the filter order");
  expect_message([&] { resample_uniform(t, x, 0.0); },
                 "resampling rate is 0 Hz: give a positive target sample rate");
  expect_message([&] { interpolate(t, x, Eigen::VectorXd::Constant(2, 0.5)); },
                 "interpolation query 0 at t = 0.5 is outside the data [0, 0.099000000000000005] "
                 "s: query only inside the recorded time span");
}

}  // namespace
}  // namespace dynid
