// Low-pass design and zero-phase filtering against the analytic prototype magnitudes.
#include <cmath>
#include <complex>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "dynid/common/error.hpp"
#include "dynid/signal/lowpass_design.hpp"
#include "dynid/signal/period_averaging.hpp"
#include "dynid/signal/periodic_filter.hpp"
#include "dynid/signal/zero_phase_filter.hpp"
#include "support/test_constants.hpp"

namespace dynid {
namespace {

using test_support::kPi;

// Independent oracle: Chebyshev polynomial T_N(x) by its trigonometric/hyperbolic closed form.
double chebyshev_t(int n, double x) {
  if (std::abs(x) <= 1.0) return std::cos(n * std::acos(x));
  const double v = std::cosh(n * std::acosh(std::abs(x)));
  return (x < 0 && n % 2 == 1) ? -v : v;
}

// Independent oracle: |H_a(jΩ)| of the analog prototype at the pre-warped frequency of f.
double analytic_magnitude(const LowpassOptions& o, double f) {
  const double r =
      std::tan(kPi * f / o.sample_rate_hz) / std::tan(kPi * o.cutoff_hz / o.sample_rate_hz);
  if (o.family == LowpassFamily::kButterworth)
    return 1.0 / std::sqrt(1.0 + std::pow(r, 2 * o.order));
  const double eps2 = std::pow(10.0, o.ripple_db / 10.0) - 1.0;
  const double t = chebyshev_t(o.order, r);
  return 1.0 / std::sqrt(1.0 + eps2 * t * t);
}

// Least-squares fit y ≈ A·sin(ωt) + B·cos(ωt) on rows [begin, end): returns (A, B).
Eigen::Vector2d fit_sine(const Eigen::VectorXd& y, double w, Eigen::Index begin, Eigen::Index end) {
  Eigen::MatrixXd phi(end - begin, 2);
  for (Eigen::Index k = begin; k < end; ++k) {
    phi(k - begin, 0) = std::sin(w * k);
    phi(k - begin, 1) = std::cos(w * k);
  }
  return phi.colPivHouseholderQr().solve(y.segment(begin, end - begin));
}

struct DesignCase {
  LowpassFamily family;
  int order;
  double cutoff, rate, ripple;
};

class LowpassDesignTest : public ::testing::TestWithParam<DesignCase> {};

// The designed sections reproduce |H_a(j·2fs·tan(ω/2))| (bilinear transform with pre-warping).
TEST_P(LowpassDesignTest, FrequencyResponseMatchesAnalyticPrototype) {
  const DesignCase c = GetParam();
  LowpassOptions o;
  o.family = c.family;
  o.order = c.order;
  o.cutoff_hz = c.cutoff;
  o.sample_rate_hz = c.rate;
  o.ripple_db = c.ripple;
  const SosFilter f = design_lowpass(o);
  EXPECT_EQ(f.order(), c.order);
  EXPECT_EQ(f.sections(), (c.order + 1) / 2);
  for (double ratio : {0.0, 0.1, 0.3, 0.5, 0.77, 0.95, 1.0, 1.05, 1.3, 2.0, 3.0}) {
    const double fr = ratio * c.cutoff;
    if (fr >= 0.5 * c.rate) continue;
    const double expected = analytic_magnitude(o, fr);
    const double got = std::abs(frequency_response(f, fr, c.rate));
    EXPECT_NEAR(got, expected, 1e-9 * std::max(expected, 1e-3)) << "f = " << fr << " Hz";
  }
  // Stable: every section's poles strictly inside the unit circle (|a2| < 1, |a1| < 1 + a2).
  for (int s = 0; s < f.sections(); ++s) {
    EXPECT_LT(std::abs(f.sos(s, 5)), 1.0);
    EXPECT_LT(std::abs(f.sos(s, 4)), 1.0 + f.sos(s, 5));
  }
}

INSTANTIATE_TEST_SUITE_P(
    Designs, LowpassDesignTest,
    ::testing::Values(DesignCase{LowpassFamily::kButterworth, 1, 50, 1000, 0},
                      DesignCase{LowpassFamily::kButterworth, 2, 50, 1000, 0},
                      DesignCase{LowpassFamily::kButterworth, 5, 120, 1000, 0},
                      DesignCase{LowpassFamily::kButterworth, 8, 80, 5000, 0},
                      DesignCase{LowpassFamily::kChebyshev1, 3, 40, 1000, 1.0},
                      DesignCase{LowpassFamily::kChebyshev1, 4, 100, 1000, 0.5},
                      DesignCase{LowpassFamily::kChebyshev1, 8, 80, 1000, 0.5},
                      DesignCase{LowpassFamily::kChebyshev1, 8, 80, 5000, 0.05},
                      DesignCase{LowpassFamily::kChebyshev1, 7, 300, 1000, 0.1}));

// Filtering sinusoids (steady state, middle of a long record) with filtfilt gives the squared
// analytic magnitude and no phase lag: the measured response, not the formula, of the code.
TEST(Filtfilt, SineSteadyStateIsSquaredMagnitudeWithZeroPhase) {
  for (double rate : {1000.0, 5000.0}) {
    for (LowpassFamily fam : {LowpassFamily::kButterworth, LowpassFamily::kChebyshev1}) {
      LowpassOptions o;
      o.family = fam;
      o.order = 8;
      o.cutoff_hz = 80.0;
      o.sample_rate_hz = rate;
      o.ripple_db = 0.5;
      const SosFilter f = design_lowpass(o);
      const Eigen::Index m = rate > 2000 ? 40000 : 12000;
      for (double fr : {5.0, 40.0, 70.0, 80.0, 90.0, 110.0}) {
        const double w = 2.0 * kPi * fr / rate;
        Eigen::VectorXd x(m);
        for (Eigen::Index k = 0; k < m; ++k) x(k) = std::sin(w * k);
        const Eigen::VectorXd y = filtfilt(f, x);
        const Eigen::Vector2d ab = fit_sine(y, w, m / 3, 2 * m / 3);
        const double h = analytic_magnitude(o, fr);
        const std::string where = "rate " + std::to_string(rate) + " f " + std::to_string(fr);
        EXPECT_NEAR(ab.norm(), h * h, 1e-7 + 1e-6 * h * h) << where;
        EXPECT_NEAR(std::atan2(ab(1), ab(0)), 0.0, 1e-6) << where;  // zero phase
      }
    }
  }
}

// A causal pass lags: its phase equals arg H(e^{jω}) (independent check of sosfilt against the
// section product), while filtfilt applied to columns treats each column independently.
TEST(Sosfilt, CausalPhaseMatchesResponseAndColumnsAreIndependent) {
  LowpassOptions o;
  o.family = LowpassFamily::kChebyshev1;
  o.order = 5;
  o.cutoff_hz = 30;
  o.sample_rate_hz = 1000;
  const SosFilter f = design_lowpass(o);
  const double fr = 20.0, w = 2.0 * kPi * fr / 1000.0;
  const Eigen::Index m = 6000;
  Eigen::MatrixXd x(m, 2);
  for (Eigen::Index k = 0; k < m; ++k) {
    x(k, 0) = std::sin(w * k);
    x(k, 1) = 3.0 - 2.0 * std::cos(0.3 * k);
  }
  const Eigen::MatrixXd y = sosfilt(f, x);
  const Eigen::Vector2d ab = fit_sine(y.col(0), w, 3000, 6000);
  const std::complex<double> h = frequency_response(f, fr, 1000.0);
  EXPECT_NEAR(ab(0), h.real(), 1e-9);  // y = |H| sin(ωk + φ) = Re H sin + Im H cos
  EXPECT_NEAR(ab(1), h.imag(), 1e-9);
  const Eigen::MatrixXd yy = filtfilt(f, x);
  EXPECT_TRUE(yy.col(1).isApprox(filtfilt(f, Eigen::VectorXd(x.col(1))), 1e-15));
}

// An even-order Chebyshev I design sits at the bottom of its ripple at DC; the identification
// filter is the same design rescaled to unit DC gain: a constant passes unchanged through the
// causal filter (independent of the section algebra), and the shape is the design's at every f.
TEST(LowpassUnitDc, EvenChebyshevPassesAConstantUnchangedAndKeepsItsShape) {
  LowpassOptions o;
  o.family = LowpassFamily::kChebyshev1;
  o.order = 8;
  o.cutoff_hz = 80;
  o.sample_rate_hz = 1000;
  o.ripple_db = 1.0;
  const SosFilter plain = design_lowpass(o), unit = design_lowpass_unit_dc(o);
  const double ripple_dc = 1.0 / std::sqrt(std::pow(10.0, 0.1 * o.ripple_db));
  EXPECT_NEAR(std::abs(frequency_response(plain, 0.0, 1000.0)), ripple_dc, 1e-9);
  const Eigen::MatrixXd y = sosfilt(unit, Eigen::MatrixXd::Constant(20000, 1, 2.5));
  EXPECT_NEAR(y(19999, 0), 2.5, 1e-9);
  for (const double f : {10.0, 60.0, 120.0}) {
    EXPECT_NEAR(std::abs(frequency_response(unit, f, 1000.0)),
                std::abs(frequency_response(plain, f, 1000.0)) / ripple_dc, 1e-9);
  }
}

// Steady-state initial conditions: a constant signal passes unchanged, at every sample.
TEST(Filtfilt, ConstantAndStepSteadyState) {
  LowpassOptions o;
  o.family = LowpassFamily::kChebyshev1;
  o.order = 8;
  o.cutoff_hz = 80;
  o.sample_rate_hz = 1000;
  const SosFilter f = design_lowpass(o);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Constant(200, 3, 2.5);
  // Chebyshev with even order has DC gain 1/sqrt(1+ε²) per pass.
  const double eps2 = std::pow(10.0, 0.5 / 10.0) - 1.0;
  EXPECT_NEAR((filtfilt(f, x).array() - 2.5 / (1.0 + eps2)).abs().maxCoeff(), 0.0, 1e-12);
  const Eigen::MatrixXd zi = sosfilt_steady_state(f);
  const Eigen::MatrixXd yc = sosfilt(f, x, zi);
  EXPECT_NEAR((yc.array() - 2.5 / std::sqrt(1.0 + eps2)).abs().maxCoeff(), 0.0, 1e-12);
  // A line is reproduced by odd reflection + steady state only approximately; a Butterworth
  // filtfilt of a ramp has zero phase, so the interior equals the ramp (DC gain 1, no lag).
  o.family = LowpassFamily::kButterworth;
  const SosFilter b = design_lowpass(o);
  Eigen::VectorXd ramp = Eigen::VectorXd::LinSpaced(3000, -1.0, 2.0);
  const Eigen::VectorXd yr = filtfilt(b, ramp);
  EXPECT_LT((yr - ramp).segment(500, 2000).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(LowpassErrors, MessagesNameInputAndFix) {
  auto expect_error = [](const LowpassOptions& o, const std::string& text) {
    try {
      design_lowpass(o);
      ADD_FAILURE() << "no error for " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  LowpassOptions o;
  o.cutoff_hz = 500;
  o.sample_rate_hz = 1000;
  expect_error(o,
               "low-pass cut-off 500 Hz is outside (0, Nyquist = 500 Hz) for sample rate 1000 "
               "Hz: lower the cut-off or use data sampled faster");
  o.cutoff_hz = 80;
  o.order = 0;
  expect_error(o, "low-pass filter order is 0: give an order of at least 1");
  o.order = 4;
  o.sample_rate_hz = -1;
  expect_error(o,
               "low-pass filter sample rate is -1 Hz: give the positive sample rate of the data");
  o.sample_rate_hz = 1000;
  o.family = LowpassFamily::kChebyshev1;
  o.ripple_db = 0;
  expect_error(o, "Chebyshev passband ripple is 0 dB: give a positive ripple (e.g. 0.5 dB)");

  o.ripple_db = 0.5;
  o.order = 8;
  const SosFilter f = design_lowpass(o);
  EXPECT_EQ(filtfilt_default_padding(f), 27);
  try {
    filtfilt(f, Eigen::VectorXd::Zero(27));
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "zero-phase filter input has 27 samples but the order-8 filter pads 27 samples "
                 "per end: give at least 28 samples or lower the filter order");
  }
  Eigen::VectorXd bad = Eigen::VectorXd::Zero(100);
  bad(5) = std::nan("");
  try {
    filtfilt(f, bad);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "zero-phase filter input contains NaN or Inf: clean or drop those samples first");
  }
  try {
    sosfilt(f, bad, Eigen::MatrixXd::Zero(3, 2));
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "sosfilt initial state is 3x2: give sections x 2 (4x2) or an empty matrix");
  }
}

// Seed 2 §3.4's filter: 8th-order Chebyshev I, 0.5 dB ripple, 80 Hz at 1 kHz.
LowpassOptions seed2_chebyshev() {
  LowpassOptions o;
  o.family = LowpassFamily::kChebyshev1;
  o.order = 8;
  o.cutoff_hz = 80.0;
  o.sample_rate_hz = 1000.0;
  o.ripple_db = 0.5;
  return o;
}

// Seed 2's chain on an averaged period (dynid average --filter chebyshev:8 --cutoff 80
// --decimate 5): one 2 s period at 1 kHz holding an in-band line (0.5 Hz, the top of seed 2's
// excitation band), an out-of-band tone (150 Hz) and a constant. The in-band line passes with the
// documented ripple: exactly the analytic prototype's |H_a|² (unit DC), within [1, 1 + eps²] for
// an even-order Chebyshev I, no phase shift; the tone is gone; the constant is kept.
TEST(PeriodicLowpass, InBandLinePassesWithTheRippleOutOfBandToneIsRemoved) {
  PeriodicLowpassOptions o;
  o.design = seed2_chebyshev();
  o.decimate = 5;
  const Eigen::Index p = 2000;
  Eigen::MatrixXd x(p, 2);
  for (Eigen::Index k = 0; k < p; ++k) {
    const double t = static_cast<double>(k) / 1000.0;
    x(k, 0) = 0.7 + std::sin(2 * kPi * 0.5 * t) + 0.3 * std::sin(2 * kPi * 150.0 * t);
    x(k, 1) = -2.0 * std::cos(2 * kPi * 0.5 * t);
  }
  const Eigen::MatrixXd y = lowpass_periodic(o, x);
  ASSERT_EQ(y.rows(), p / 5);
  ASSERT_EQ(y.cols(), 2);
  // Oracle: the analog prototype's magnitude at the pre-warped frequency (not the sections).
  const double eps2 = std::pow(10.0, 0.5 / 10.0) - 1.0;
  const double dc = analytic_magnitude(o.design, 0.0);
  const double g = std::pow(analytic_magnitude(o.design, 0.5) / dc, 2);
  EXPECT_GE(g, 1.0 - 1e-12);
  EXPECT_LE(g, 1.0 + eps2);
  const double tone = std::pow(analytic_magnitude(o.design, 150.0) / dc, 2);
  EXPECT_LT(tone, 1e-7);  // -140 dB over the two passes
  double worst = 0.0, in_band = 0.0;
  for (Eigen::Index k = 0; k < y.rows(); ++k) {
    const double t = static_cast<double>(5 * k) / 1000.0;
    const double line = 0.7 + g * std::sin(2 * kPi * 0.5 * t);
    worst = std::max(worst, std::abs(y(k, 0) - line - 0.3 * tone * std::sin(2 * kPi * 150 * t)));
    worst = std::max(worst, std::abs(y(k, 1) + 2.0 * g * std::cos(2 * kPi * 0.5 * t)));
    in_band = std::max(in_band, std::abs(y(k, 0) - line));
  }
  EXPECT_LT(worst, 1e-10);
  EXPECT_LT(in_band, 0.3e-7);  // what is left of the tone
}

// Independent algorithm: the time-domain forward-backward filter (filtfilt) on the period
// repeated 11 times, middle period, is the circular filter's result once the edge transient has
// died out (an 80 Hz Chebyshev's slowest pole decays in ~100 samples; 5 periods of 300 samples
// separate the middle from the edges).
TEST(PeriodicLowpass, EqualsTheSteadyStateOfFiltfiltOnTheRepeatedPeriod) {
  const SosFilter f = design_lowpass_unit_dc(seed2_chebyshev());
  const Eigen::Index p = 300, repeats = 11;
  Eigen::MatrixXd x = Eigen::MatrixXd::Random(p, 2);  // fixed seed: Eigen's default rand()
  Eigen::MatrixXd long_x(p * repeats, 2);
  for (Eigen::Index r = 0; r < repeats; ++r) long_x.middleRows(r * p, p) = x;
  const Eigen::MatrixXd expected = filtfilt(f, long_x).middleRows(5 * p, p);
  const Eigen::MatrixXd y = filtfilt_periodic(f, x);
  EXPECT_LT((y - expected).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(PeriodicLowpass, DecimationThatBreaksThePeriodOrAliasesIsAnError) {
  PeriodicLowpassOptions o;
  o.design = seed2_chebyshev();
  const Eigen::MatrixXd x = Eigen::MatrixXd::Ones(2000, 1);
  o.decimate = 3;
  try {
    lowpass_periodic(o, x);
    ADD_FAILURE() << "no error for a factor that does not divide the period";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "decimation by 3 does not divide the period's 2000 samples: the kept samples would "
              "not be evenly spaced across the period's wrap; use a factor that divides it (2, 4, "
              "5, 8, 10, 16, 20, 25, 40, 50)");
  }
  o.decimate = 10;  // new Nyquist 50 Hz, below the 80 Hz cut-off
  try {
    lowpass_periodic(o, x);
    ADD_FAILURE() << "no error for an aliasing decimation";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "cut-off 80 Hz is not below the decimated Nyquist rate 50 Hz (rate 1000 Hz / (2 x "
              "10)): the decimation would alias; lower the cut-off or the decimation factor");
  }
  EXPECT_THROW(filtfilt_periodic(design_lowpass(o.design), Eigen::MatrixXd::Constant(10, 1, NAN)),
               Error);
}

}  // namespace
// dynid average's row selection: the listed columns low-passed (as lowpass_periodic() alone), the
// others (references) and the phase taken at the same kept rows 0, N, 2N, … unfiltered.
TEST(PeriodicLowpass, ColumnsNotListedAndThePhaseKeepTheKeptRowsAsGiven) {
  PeriodicLowpassOptions o;
  o.design = seed2_chebyshev();
  o.decimate = 5;
  const Eigen::Index p = 2000;
  const Eigen::MatrixXd x = Eigen::MatrixXd::Random(p, 3);
  const Eigen::VectorXd phase = Eigen::VectorXd::LinSpaced(p, 0.0, 1.999);
  const LowpassedPeriod r = lowpass_period_columns(o, phase, x, {0, 2});
  ASSERT_EQ(r.x.rows(), p / 5);
  ASSERT_EQ(r.phase.size(), p / 5);
  Eigen::MatrixXd measured(p, 2);
  measured << x.col(0), x.col(2);
  const Eigen::MatrixXd low = lowpass_periodic(o, measured);
  for (Eigen::Index k = 0; k < r.x.rows(); ++k) {
    EXPECT_EQ(r.phase[k], phase[5 * k]);
    EXPECT_EQ(r.x(k, 1), x(5 * k, 1));
    EXPECT_EQ(r.x(k, 0), low(k, 0));
    EXPECT_EQ(r.x(k, 2), low(k, 1));
  }
  EXPECT_THROW(lowpass_period_columns(o, phase.head(10), x, {0}), Error);
  EXPECT_THROW(lowpass_period_columns(o, phase, x, {3}), Error);
}

// averaged_noise_std() against a Monte-Carlo of seed 2's chain: white noise (σ = 1 at 1 kHz) in
// K = 8 periods of 1000 samples, averaged (average_periods), low-passed by seed 2's Chebyshev at
// 80 Hz and decimated by 5 (dynid average). What identify does with it is filter it again inside
// the band: here a 20 Hz low-pass at 200 Hz, whose output variance for a white input of std s is
// s²·mean_b |G_b|⁴. The measured variance over 100 realisations (≈ 4000 independent values:
// ±2.2 %) matches s = averaged_noise_std() to 5 % (0.993). Without the Chebyshev's pass-band
// gain γ = 1.124 (s² = 1/(K·N)) it is off by 12 %, with the per-sample std of the mean (1/√K) by
// a factor 5.
TEST(AveragedNoise, IsTheWhiteEquivalentOfTheMeanPeriodInTheBand) {
  constexpr int kPeriods = 8, kRuns = 100, kDecimate = 5;
  const Eigen::Index p = 1000;
  PeriodicLowpassOptions o;
  o.design = seed2_chebyshev();
  o.decimate = kDecimate;
  LowpassOptions inner;
  inner.family = LowpassFamily::kButterworth;
  inner.order = 4;
  inner.cutoff_hz = 20.0;
  inner.sample_rate_hz = 200.0;
  const SosFilter g = design_lowpass_unit_dc(inner);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> z;
  double measured = 0.0;
  for (int r = 0; r < kRuns; ++r) {
    Eigen::MatrixXd x(p * kPeriods, 1);
    for (Eigen::Index k = 0; k < x.rows(); ++k) x(k, 0) = z(rng);
    const PeriodAverage a = average_periods(x, static_cast<int>(p));
    const Eigen::MatrixXd y = filtfilt_periodic(g, lowpass_periodic(o, a.mean));
    measured += y.squaredNorm() / static_cast<double>(y.size() * kRuns);
  }
  // A white noise of std s through filtfilt_periodic(g): each of the P/N bins scaled by |G|².
  const Eigen::Index rows = p / kDecimate;
  double gain4 = 0.0;
  for (Eigen::Index b = 0; b < rows; ++b) {
    const double cycles = static_cast<double>(b <= rows / 2 ? b : rows - b) / rows;
    gain4 += std::pow(std::norm(frequency_response(g, cycles, 1.0)), 2) / rows;
  }
  const double s = averaged_noise_std(1.0, kPeriods, &o);
  EXPECT_NEAR(averaged_noise_std(1.0, kPeriods), 1.0 / std::sqrt(8.0), 1e-15);
  EXPECT_NEAR(s * s * 40.0, 1.124, 1e-3);  // γ of the 0.5 dB Chebyshev (measured 0.993 ratio)
  EXPECT_NEAR(measured / (s * s * gain4), 1.0, 0.05);
  EXPECT_THROW(averaged_noise_std(-1.0, kPeriods), Error);
  EXPECT_THROW(averaged_noise_std(1.0, 0), Error);
}

}  // namespace dynid
