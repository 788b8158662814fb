#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/signal/periodic_filter.hpp"

namespace dynid {

/// Options of average_periods.
struct PeriodAverageOptions {
  int skip_periods = 0;  ///< leading periods dropped (start-up transient of the experiment)
};

/// The mean period of a periodic experiment and its noise statistics.
struct PeriodAverage {
  Eigen::MatrixXd mean;  ///< P × n: x̄_k = (1/K)·Σ_i x_{iP+k}; its noise variance is variance/K
  Eigen::MatrixXd variance;  ///< P × n: s²_k = Σ_i (x_{iP+k} − x̄_k)²/(K − 1) (unbiased)
  Eigen::VectorXd channel_variance;  ///< n: (1/P)·Σ_k s²_k, pooled noise variance per channel
  int periods = 0;                   ///< K, number of periods averaged
  int period_samples = 0;            ///< P
  int unused_samples = 0;            ///< trailing samples of an incomplete period (ignored)
};

/// Averages the K complete periods of x (m × n, samples × channels, period P samples) into one
/// mean period and estimates the measurement noise from the spread across periods (seed 2 §3.4:
/// 25 repetitions averaged, the noise PDF computed from them). Assumes the period is an integer
/// number of samples (sample the experiment with fs·T integer, or resample first).
/// Throws dynid::Error for P < 1, skip_periods < 0, or fewer than 2 complete periods after the
/// skipped ones (the message says how many samples are needed).
PeriodAverage average_periods(const Eigen::Ref<const Eigen::MatrixXd>& x, int period_samples,
                              const PeriodAverageOptions& options = {});

/// Options of detect_period.
struct PeriodDetectionOptions {
  int min_period = 2;          ///< smallest period considered [samples]
  int max_period = -1;         ///< largest period considered; −1 = m/2 (at least two periods)
  double peak_fraction = 0.9;  ///< the period is the smallest lag whose correlation is a local
                               ///< maximum ≥ peak_fraction·(best correlation in the range)
};

/// Detects the period [samples] of a (reference) signal from its normalised autocorrelation
/// r(L) = Σ_k y_k y_{k+L} / sqrt(Σ_k y_k² · Σ_k y_{k+L}²) over the overlap, y = x − mean(x),
/// computed with an FFT (O(m log m)). r(P) = 1 for an exactly P-periodic signal; multiples of P
/// score as high, so the smallest lag near the best score is returned.
/// Throws dynid::Error for a constant signal, a range that is empty or does not fit two periods
/// into m samples, or when no correlation peak is found in the range.
int detect_period(const Eigen::Ref<const Eigen::VectorXd>& reference,
                  const PeriodDetectionOptions& options = {});

/// Options of average_periods_in_time().
struct TimedPeriodAverageOptions {
  double start = std::numeric_limits<double>::quiet_NaN();  ///< time of the first period's start
                                                            ///< [s]; NaN = the first sample's t
  int skip_periods = 0;  ///< complete periods dropped after start (start-up transient)
};

/// Noise statistics of one channel from its residuals about the mean period.
struct ChannelNoise {
  double std = 0.0;          ///< noise standard deviation (unbiased variance, see below)
  double skewness = 0.0;     ///< third standardised moment (0 for Gaussian); NaN if std = 0
  double kurtosis = 0.0;     ///< fourth standardised moment (3 for Gaussian); NaN if std = 0
  double normality_p = 0.0;  ///< D'Agostino–Pearson K² test p-value; NaN if std = 0
};

/// The mean period of a run with a period given in seconds, and per channel noise statistics.
struct TimedPeriodAverage {
  Eigen::VectorXd phase;  ///< P phase times k·T/P [s] from the period start, P = round(T/Ts)
  Eigen::MatrixXd
      mean;  ///< P × c mean period: average over the periods of x at start + i·T + phase
  std::vector<ChannelNoise> channels;  ///< per column of x
  int periods = 0;                     ///< complete periods averaged (after skip_periods)
  double samples_per_period = 0.0;     ///< T/Ts, not necessarily an integer
  bool interpolated = false;           ///< T/Ts or the start not on the sample grid
  double start = 0.0;                  ///< first period's start [s]
  double sample_time = 0.0;            ///< Ts [s], mean step of t
  long samples_before = 0;             ///< samples before the first averaged period (not used)
  long samples_after = 0;              ///< samples after the last complete period (not used)
  double partial_period = 0.0;         ///< fraction of a period left after the last complete one
  long residual_samples = 0;           ///< samples whose residuals give the statistics
};

/// Averages the complete periods of x (m × c, rows at the uniformly spaced times t) for a period
/// of `period` seconds that need not be a whole number of samples, and a first period starting at
/// any time (seed 2 §3.4 and Fig. 5: 25 repetitions averaged, noise PDF from them). Values between
/// samples come from 4-point Lagrange (cubic) interpolation in the sample index, so the periods'
/// start times may drift across the sample grid; on the grid the weights are exactly 0/1.
/// Noise: each sample s of period i gets the residual e_s = x_s − mean_{j≠i} x(start + j·T + φ_s)
/// (leave-one-out, so e_s holds that sample's own noise); with white noise of variance σ²,
/// E[e_s²] = σ²·c_s, c_s = 1 + Σ_j Σ w²/(K − 1)² from the interpolation weights w, and
/// σ̂² = mean(e_s²/c_s) is unbiased. skewness = m3(e)/σ̂³, kurtosis = 3 + (m4(e) − 3·m2(e)²)/σ̂⁴
/// (the averaged term is nearly Gaussian and independent of the sample's noise, so e's third and
/// fourth cumulants are the noise's). normality_p: dagostino_pearson() on the residuals.
/// Throws dynid::Error for t not uniform (rel. 1e-6) or not matching x, non-finite x, period not
/// finite or ≤ 2 samples, start outside the run, skip_periods < 0, or fewer than 2 complete
/// periods (the message gives the run length and the period).
TimedPeriodAverage average_periods_in_time(const Eigen::Ref<const Eigen::VectorXd>& t,
                                           const Eigen::Ref<const Eigen::MatrixXd>& x,
                                           double period,
                                           const TimedPeriodAverageOptions& options = {});

/// Noise std of the mean period as a white noise at its own rate, for a raw white noise of std
/// `raw_std` (ChannelNoise::std): raw_std·√(γ/(K·N)), K = `periods` averaged, N the decimation
/// and γ the mean of |H|⁴ over the pass band [0, cut-off] of the circular low-pass of `lowpass`
/// (lowpass_periodic(); null: no filter, N = γ = 1). Identity: in the band the mean's spectral
/// density is the raw one over K times |H|⁴ (forward and backward pass), and a white noise of that
/// density at the rate fs/N has variance raw_std²·γ/(K·N); this is the std that processed_noise()
/// carries through identify's filter and differences when the mean period is the data
/// (docs/methods/signal.md "Noise of the mean period"). γ: 1 for a Butterworth to 1e-2, about
/// 1.12 for seed 2's 0.5 dB Chebyshev (unit DC gain at a ripple valley). Interpolation between
/// samples does not change the density in the band. Throws dynid::Error for raw_std < 0 or not
/// finite, periods < 1, and as design_lowpass().
double averaged_noise_std(double raw_std, int periods,
                          const PeriodicLowpassOptions* lowpass = nullptr);

/// True for the name of a reference channel: qr<J>, dqr<J>, ddqr<J> (the controller's noise-free
/// command and its analytic derivatives, as `dynid simulate` logs them).
bool is_reference_channel(const std::string& name);

/// Checks that a run repeats with the period it was averaged with (a wrong --period/--f0 averages
/// unrelated samples and reports the signal's own variation as noise, a silently wrong result).
/// `names` labels the columns of `x`, the data given to average_periods_in_time() with result `a`.
/// A reference channel (is_reference_channel()) is noise-free: its spread across periods (its
/// ChannelNoise::std) above 1 % of its range means the period is wrong; the error names the
/// channel, the spread and the period detect_period() finds in it. A position channel (q<J>)
/// spreading by more than 10 % of its range gives a returned warning (noise, drift or a wrong
/// period: without a reference the run cannot tell which), unless its whole range is noise: a
/// held joint, range ≤ 12 σ_d with σ_d = RMS(second differences)/√6 its sample-to-sample noise
/// (a constant repeats with any period; its spread is then its noise, a large part of its range).
/// Throws dynid::Error for a reference channel that does not repeat, or sizes that do not match.
std::vector<std::string> check_period_repeats(const TimedPeriodAverage& a,
                                              const Eigen::Ref<const Eigen::MatrixXd>& x,
                                              const std::vector<std::string>& names);

/// Result of a normality test.
struct NormalityTest {
  double skewness = 0.0;  ///< sample skewness g1 = m3/m2^{3/2}
  double kurtosis = 0.0;  ///< sample kurtosis b2 = m4/m2² (3 for Gaussian)
  double k2 = 0.0;        ///< Z1² + Z2²
  double p = 0.0;         ///< P(χ²₂ > K²) = exp(−K²/2)
};

/// D'Agostino–Pearson omnibus K² test of normality (R. B. D'Agostino, A. Belanger, R. B.
/// D'Agostino Jr., "A suggestion for using powerful and informative tests of normality", The
/// American Statistician 44(4), 1990): Z1 from the skewness (D'Agostino 1970), Z2 from the
/// kurtosis (Anscombe–Glynn 1983), K² = Z1² + Z2² ~ χ²₂ under normality. Needs n ≥ 20 samples.
/// Throws dynid::Error for n < 20, non-finite values, or zero variance.
NormalityTest dagostino_pearson(const Eigen::Ref<const Eigen::VectorXd>& x);

}  // namespace dynid
