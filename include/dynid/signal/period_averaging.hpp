#pragma once

#include <Eigen/Core>

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

}  // namespace dynid
