// Noise floor, signal edge and automatic cut-off (issue 9 item 2): known sinusoids plus white
// noise of known σ, and the noise gain of the velocity processing against its closed form and a
// Monte-Carlo run.
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "dynid/common/error.hpp"
#include "dynid/signal/lowpass_design.hpp"
#include "dynid/signal/noise_floor.hpp"
#include "dynid/signal/zero_phase_filter.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

// Two joints at `rate` for `seconds` plus white noise σ: joint 1 a robot-like motion, harmonics of
// 0.3 Hz up to `top` Hz with amplitudes 1/k (a contiguous band); joint 2 one 0.3 Hz sinusoid and,
// with `spur`, a small isolated 20 Hz line more than an octave above it (a loop resonance).
Eigen::MatrixXd sinusoids(double rate, double seconds, double top, double sigma, unsigned seed,
                          bool spur = false) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, sigma);
  const auto m = static_cast<Eigen::Index>(rate * seconds);
  const int harmonics = static_cast<int>(std::floor(top / 0.3 + 1e-9));
  Eigen::MatrixXd q(m, 2);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = k / rate;
    q(k, 0) = n(rng);
    for (int h = 1; h <= harmonics; ++h) q(k, 0) += std::sin(2 * kPi * 0.3 * h * t + h) / h;
    q(k, 1) = 0.5 * std::cos(2 * kPi * 0.3 * t) + n(rng);
    if (spur) q(k, 1) += 0.05 * std::sin(2 * kPi * 20.0 * t);
  }
  return q;
}

TEST(NoiseFloor, RecoversTheNoiseStdAndTheMotionsBand) {
  for (double rate : {100.0, 1000.0, 5000.0}) {
    const Eigen::MatrixXd q = sinusoids(rate, 60.0, 3.0, 1e-3, 5, rate > 100.0);
    const NoiseFloor f = position_noise_floor(q, rate);
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(f.noise_std[j], 1e-3, 1e-4) << rate;
    // The band of the highest harmonic (3 Hz, 20 dB above the floor) or the next one (leakage).
    EXPECT_GT(f.signal_edge_hz[0], 2.4) << rate;
    EXPECT_LT(f.signal_edge_hz[0], 4.5) << rate;
    // The isolated 20 Hz line beyond an octave of floor is not part of the motion's band.
    EXPECT_GT(f.signal_edge_hz[1], 0.2) << rate;
    EXPECT_LT(f.signal_edge_hz[1], 0.6) << rate;
  }
}

TEST(NoiseFloor, CutoffIsOneAndAHalfTimesTheEdgeWithinItsBounds) {
  const Eigen::MatrixXd q = sinusoids(1000.0, 60.0, 3.0, 1e-3, 6);
  const CutoffChoice c = choose_cutoff(q, 1000.0);
  EXPECT_NEAR(c.cutoff_hz, 1.5 * c.floor.signal_edge_hz.maxCoeff(), 1e-12);
  EXPECT_NE(c.reason.find("noise floor"), std::string::npos) << c.reason;
  // No visible noise floor: the upper bound min(20 Hz, rate/10).
  const Eigen::MatrixXd clean = sinusoids(100.0, 60.0, 3.0, 0.0, 6);
  EXPECT_NEAR(choose_cutoff(clean, 100.0).cutoff_hz, 10.0, 1e-12);
  // A slow motion under heavy noise: the lower bound, 1 Hz.
  const Eigen::MatrixXd slow = sinusoids(1000.0, 60.0, 0.3, 0.05, 7);
  EXPECT_NEAR(choose_cutoff(slow, 1000.0).cutoff_hz, 1.0, 1e-12);
  // Too short for a spectrum: the upper bound and NaN floors.
  const CutoffChoice s = choose_cutoff(q.topRows(100), 1000.0);
  EXPECT_NEAR(s.cutoff_hz, 20.0, 1e-12);
  EXPECT_TRUE(std::isnan(s.floor.noise_std[0]));
  EXPECT_THROW(choose_cutoff(q, 0.0), Error);
}

TEST(NoiseFloor, VelocityNoiseGainMatchesClosedFormAndMonteCarlo) {
  // Central differences alone: (n_{k+1} − n_{k−1})·rate/2 has std σ·rate/√2.
  EXPECT_NEAR(white_noise_gain(nullptr, 1, 500.0), 500.0 / std::sqrt(2.0), 1e-9);
  EXPECT_NEAR(white_noise_gain(nullptr, 0, 500.0), 1.0, 1e-12);
  LowpassOptions lp;
  lp.cutoff_hz = 5.0;
  lp.sample_rate_hz = 1000.0;
  const SosFilter f = design_lowpass(lp);
  std::mt19937 rng(9);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd x(4000000, 1);
  for (Eigen::Index k = 0; k < x.rows(); ++k) x(k, 0) = n01(rng);
  const Eigen::MatrixXd y = filtfilt(f, x);
  const Eigen::Index inner = x.rows() - 20000;
  const Eigen::VectorXd mid = y.col(0).segment(10000, inner);
  Eigen::VectorXd d(inner - 2);
  for (Eigen::Index k = 1; k + 1 < inner; ++k) d[k - 1] = 500.0 * (mid[k + 1] - mid[k - 1]);
  const double sd_y = std::sqrt(mid.squaredNorm() / inner),
               sd_d = std::sqrt(d.squaredNorm() / d.size());
  EXPECT_NEAR(white_noise_gain(&f, 0, 1000.0), sd_y, 0.03 * sd_y);
  EXPECT_NEAR(white_noise_gain(&f, 1, 1000.0), sd_d, 0.03 * sd_d);
  EXPECT_THROW(white_noise_gain(&f, 3, 1000.0), Error);
}

}  // namespace
}  // namespace dynid
