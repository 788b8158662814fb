#include "dynid/signal/period_averaging.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"

namespace dynid {

PeriodAverage average_periods(const Eigen::Ref<const Eigen::MatrixXd>& x, int period_samples,
                              const PeriodAverageOptions& options) {
  const int p = period_samples;
  if (p < 1) {
    throw Error("period is " + std::to_string(p) +
                " samples: give the period of the experiment in samples (>= 1)");
  }
  if (options.skip_periods < 0) {
    throw Error("skip_periods is " + std::to_string(options.skip_periods) +
                ": give a non-negative number of leading periods to drop");
  }
  const Eigen::Index start = static_cast<Eigen::Index>(options.skip_periods) * p;
  const Eigen::Index usable = std::max<Eigen::Index>(x.rows() - start, 0);
  const int k = static_cast<int>(usable / p);
  if (k < 2) {
    throw Error("period averaging needs at least 2 complete periods of " + std::to_string(p) +
                " samples after skipping " + std::to_string(options.skip_periods) +
                " periods, i.e. " + std::to_string(start + 2 * static_cast<Eigen::Index>(p)) +
                " samples, but got " + std::to_string(x.rows()) +
                ": record more periods or check the period");
  }
  PeriodAverage out;
  out.periods = k;
  out.period_samples = p;
  out.unused_samples = static_cast<int>(usable - static_cast<Eigen::Index>(k) * p);
  out.mean = Eigen::MatrixXd::Zero(p, x.cols());
  for (int i = 0; i < k; ++i) out.mean += x.middleRows(start + static_cast<Eigen::Index>(i) * p, p);
  out.mean /= k;
  // Two-pass (centred) variance: numerically safe for large offsets.
  out.variance = Eigen::MatrixXd::Zero(p, x.cols());
  for (int i = 0; i < k; ++i) {
    out.variance +=
        (x.middleRows(start + static_cast<Eigen::Index>(i) * p, p) - out.mean).cwiseAbs2();
  }
  out.variance /= (k - 1);
  out.channel_variance = out.variance.colwise().mean().transpose();
  return out;
}

int detect_period(const Eigen::Ref<const Eigen::VectorXd>& reference,
                  const PeriodDetectionOptions& options) {
  const Eigen::Index m = reference.size();
  const Eigen::Index max_lag = options.max_period < 0 ? m / 2 : options.max_period;
  if (options.min_period < 1 || max_lag < options.min_period || 2 * max_lag > m) {
    throw Error("period search range [" + std::to_string(options.min_period) + ", " +
                std::to_string(max_lag) + "] samples does not fit two periods into the " +
                std::to_string(m) +
                " samples given: use 1 <= min_period <= max_period <= " + std::to_string(m / 2));
  }
  const Eigen::VectorXd y = reference.array() - reference.mean();
  if (!y.allFinite() || y.squaredNorm() <= 1e-300) {
    throw Error(
        "period detection reference signal is constant or contains NaN/Inf: give the commanded "
        "trajectory of a moving joint");
  }
  // Autocorrelation by FFT of the zero-padded signal: R(L) = Σ_k y_k y_{k+L}.
  int nfft = 1;
  while (nfft < 2 * m) nfft *= 2;
  std::vector<double> buf(nfft, 0.0);
  for (Eigen::Index i = 0; i < m; ++i) buf[i] = y(i);
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spec;
  fft.fwd(spec, buf);
  for (auto& s : spec) s = std::norm(s);
  std::vector<double> r;
  fft.inv(r, spec);
  // Energies of the overlapping head y_0..y_{m−1−L} and tail y_L..y_{m−1} from cumulative sums.
  std::vector<double> cum(m + 1, 0.0);
  for (Eigen::Index i = 0; i < m; ++i) cum[i + 1] = cum[i] + y(i) * y(i);
  auto corr = [&](Eigen::Index lag) {
    const double head = cum[m - lag], tail = cum[m] - cum[lag];
    return r[lag] / std::sqrt(std::max(head * tail, 1e-300));
  };
  double best = -1.0;
  for (Eigen::Index lag = options.min_period; lag <= max_lag; ++lag)
    best = std::max(best, corr(lag));
  for (Eigen::Index lag = options.min_period; lag <= max_lag; ++lag) {
    const double c = corr(lag);
    if (c < options.peak_fraction * best || c <= 0.0) continue;
    const bool left = lag - 1 < 1 || c >= corr(lag - 1);
    const bool right = lag + 1 >= m || c >= corr(lag + 1);
    if (left && right) return static_cast<int>(lag);
  }
  throw Error("no autocorrelation peak found between " + std::to_string(options.min_period) +
              " and " + std::to_string(max_lag) +
              " samples: widen the period range or give the period explicitly");
}

}  // namespace dynid
