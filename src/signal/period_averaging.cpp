#include "dynid/signal/period_averaging.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/signal/sampling_check.hpp"

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

namespace dynid {

namespace {

// 4-point Lagrange interpolation weights at fractional sample position pos (nodes base..base+3,
// clamped inside [0, n)): exactly 0/1 when pos is a sample.
struct Stencil {
  Eigen::Index base = 0;
  double w[4] = {0, 0, 0, 0};
};

Stencil lagrange4(double pos, Eigen::Index n) {
  Stencil st;
  st.base = std::clamp<Eigen::Index>(static_cast<Eigen::Index>(std::floor(pos)) - 1, 0, n - 4);
  const double u = pos - static_cast<double>(st.base);
  st.w[0] = -(u - 1) * (u - 2) * (u - 3) / 6.0;
  st.w[1] = u * (u - 2) * (u - 3) / 2.0;
  st.w[2] = -u * (u - 1) * (u - 3) / 2.0;
  st.w[3] = u * (u - 1) * (u - 2) / 6.0;
  return st;
}

// A value within 1e-9 (relative) of an integer is that integer: whole-sample periods and starts
// then use the samples themselves, with no interpolation.
double snap(double v) {
  const double r = std::round(v);
  return std::abs(v - r) <= 1e-9 * std::max(1.0, std::abs(v)) ? r : v;
}

}  // namespace

NormalityTest dagostino_pearson(const Eigen::Ref<const Eigen::VectorXd>& x) {
  const double n = static_cast<double>(x.size());
  if (x.size() < 20)
    throw Error("normality test needs at least 20 samples, got " + std::to_string(x.size()));
  if (!x.allFinite()) throw Error("normality test: the samples contain NaN or Inf");
  const Eigen::ArrayXd d = x.array() - x.mean();
  const double m2 = d.square().mean(), m3 = d.cube().mean(), m4 = d.square().square().mean();
  if (!(m2 > 0.0)) throw Error("normality test: the samples have zero variance");
  NormalityTest out;
  out.skewness = m3 / std::pow(m2, 1.5);
  out.kurtosis = m4 / (m2 * m2);
  // Z1: D'Agostino (1970) transformation of the skewness.
  const double y = out.skewness * std::sqrt((n + 1) * (n + 3) / (6 * (n - 2)));
  const double beta2 =
      3 * (n * n + 27 * n - 70) * (n + 1) * (n + 3) / ((n - 2) * (n + 5) * (n + 7) * (n + 9));
  const double w2 = -1 + std::sqrt(2 * (beta2 - 1));
  const double delta = 1 / std::sqrt(0.5 * std::log(w2));
  const double alpha = std::sqrt(2 / (w2 - 1));
  const double ya = y / alpha;
  const double z1 = delta * std::log(ya + std::sqrt(ya * ya + 1));
  // Z2: Anscombe–Glynn (1983) transformation of the kurtosis.
  const double e = 3 * (n - 1) / (n + 1);
  const double var = 24 * n * (n - 2) * (n - 3) / ((n + 1) * (n + 1) * (n + 3) * (n + 5));
  const double xk = (out.kurtosis - e) / std::sqrt(var);
  const double sqrt_beta1 = 6 * (n * n - 5 * n + 2) / ((n + 7) * (n + 9)) *
                            std::sqrt(6 * (n + 3) * (n + 5) / (n * (n - 2) * (n - 3)));
  const double a =
      6 + 8 / sqrt_beta1 * (2 / sqrt_beta1 + std::sqrt(1 + 4 / (sqrt_beta1 * sqrt_beta1)));
  const double term = (1 - 2 / a) / (1 + xk * std::sqrt(2 / (a - 4)));
  const double z2 = ((1 - 2 / (9 * a)) - std::cbrt(term)) / std::sqrt(2 / (9 * a));
  out.k2 = z1 * z1 + z2 * z2;
  out.p = std::exp(-0.5 * out.k2);  // χ² with 2 degrees of freedom
  return out;
}

TimedPeriodAverage average_periods_in_time(const Eigen::Ref<const Eigen::VectorXd>& t,
                                           const Eigen::Ref<const Eigen::MatrixXd>& x,
                                           double period,
                                           const TimedPeriodAverageOptions& options) {
  check_time_rows("period averaging", t, x);
  const SamplingInfo info = require_uniform_sampling(t, 1e-6, "period averaging");
  if (!x.allFinite()) throw Error("period averaging: the data contain NaN or Inf values");
  const Eigen::Index n = t.size();
  const double ts = info.mean_period;
  if (!std::isfinite(period) || !(period >= 2 * ts))
    throw Error("period " + short_number(period) + " s must be finite and at least two samples (" +
                short_number(2 * ts) + " s): give the excitation's period or fundamental");
  if (options.skip_periods < 0)
    throw Error("skip_periods is " + std::to_string(options.skip_periods) +
                ": give a non-negative number of leading periods to drop");
  const double start = std::isnan(options.start) ? t[0] : options.start;
  if (!std::isfinite(start) || start < t[0] - 1e-9 * ts || start > t[n - 1])
    throw Error("period start " + short_number(start) + " s is outside the run [" +
                short_number(t[0]) + ", " + short_number(t[n - 1]) + "] s");
  const double pf = snap(period / ts);          // samples per period
  const double s0 = snap((start - t[0]) / ts);  // first period's start [samples]
  const int p = static_cast<int>(std::lround(pf));
  const double step = pf / p;  // phase step [samples], 1 when pf is whole
  // Period i is complete when its last phase point lies on or before the last sample.
  const double last_phase = (p - 1) * step;
  const long total = static_cast<long>(std::floor((n - 1 - s0 - last_phase) / pf + 1e-9)) + 1;
  const long k = total - options.skip_periods;
  if (k < 2 || n < 4) {
    throw Error("period " + short_number(period) + " s gives " + std::to_string(std::max(k, 0L)) +
                " complete period(s) in the run of " + short_number(n * ts) + " s (" +
                std::to_string(n) + " samples from t = " + short_number(start) + " s, skipping " +
                std::to_string(options.skip_periods) +
                "); averaging needs at least 2: check --period/--f0 or record more periods");
  }
  const long first = options.skip_periods;
  TimedPeriodAverage out;
  out.periods = static_cast<int>(k);
  out.samples_per_period = pf;
  out.interpolated = pf != std::round(pf) || s0 != std::round(s0);
  out.start = start;
  out.sample_time = ts;
  const Eigen::Index c = x.cols();
  out.phase.resize(p);
  out.mean = Eigen::MatrixXd::Zero(p, c);
  for (int q = 0; q < p; ++q) {
    out.phase[q] = q * step * ts;
    for (long i = first; i < total; ++i) {
      const Stencil st = lagrange4(s0 + i * pf + q * step, n);
      for (int a = 0; a < 4; ++a) out.mean.row(q) += st.w[a] * x.row(st.base + a);
    }
  }
  out.mean /= static_cast<double>(k);

  // Leave-one-out residuals of the samples inside the averaged periods.
  const auto begin = static_cast<Eigen::Index>(std::ceil(s0 + first * pf - 1e-9));
  const auto end =
      std::min<Eigen::Index>(n, static_cast<Eigen::Index>(std::ceil(s0 + total * pf - 1e-9)));
  out.samples_before = begin;
  out.samples_after = n - end;
  out.partial_period = std::max(0.0, (n - (s0 + total * pf)) / pf);
  const Eigen::Index m = end - begin;
  out.residual_samples = m;
  Eigen::MatrixXd e(m, c);
  Eigen::VectorXd gain(m);  // c_s = Var(e_s)/σ²
  Eigen::RowVectorXd others(c);
  for (Eigen::Index s = begin; s < end; ++s) {
    if (!out.interpolated) {
      // On the grid the other periods' values are samples: the leave-one-out mean is
      // (K·x̄ − x_s)/(K − 1), O(1) per sample instead of O(K).
      const auto q = static_cast<Eigen::Index>(s - static_cast<Eigen::Index>(s0)) % p;
      e.row(s - begin) = (x.row(s) - out.mean.row(q)) * (static_cast<double>(k) / (k - 1));
      gain[s - begin] = 1.0 + 1.0 / static_cast<double>(k - 1);
      continue;
    }
    const long i =
        std::clamp<long>(static_cast<long>(std::floor((s - s0) / pf + 1e-9)), first, total - 1);
    const double phi = (s - s0) - i * pf;
    others.setZero();
    double g = 0.0;
    for (long j = first; j < total; ++j) {
      if (j == i) continue;
      const Stencil st = lagrange4(s0 + j * pf + phi, n);
      for (int a = 0; a < 4; ++a) {
        others += st.w[a] * x.row(st.base + a);
        g += st.w[a] * st.w[a];
      }
    }
    e.row(s - begin) = x.row(s) - others / static_cast<double>(k - 1);
    gain[s - begin] = 1.0 + g / (static_cast<double>(k - 1) * (k - 1));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index col = 0; col < c; ++col) {
    ChannelNoise ch;
    const double var = (e.col(col).array().square() / gain.array()).mean();
    const double scale = x.col(col).cwiseAbs().maxCoeff();
    // Rounding-level residuals (an exactly periodic reference column) are no noise.
    if (!(var > 1e-24 * scale * scale) || m < 20) {
      ch.std = var > 1e-24 * scale * scale ? std::sqrt(var) : 0.0;
      ch.skewness = ch.kurtosis = ch.normality_p = nan;
    } else {
      ch.std = std::sqrt(var);
      const Eigen::ArrayXd d = e.col(col).array() - e.col(col).mean();
      const double m2 = d.square().mean(), m3 = d.cube().mean(), m4 = d.square().square().mean();
      ch.skewness = m3 / (var * ch.std);
      ch.kurtosis = 3.0 + (m4 - 3.0 * m2 * m2) / (var * var);
      ch.normality_p = dagostino_pearson(e.col(col)).p;
    }
    out.channels.push_back(ch);
  }
  return out;
}

namespace {

bool has_index_suffix(const std::string& name, const std::string& prefix) {
  return name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0 &&
         name.find_first_not_of("0123456789", prefix.size()) == std::string::npos;
}

// A noise-free reference repeats to its interpolation error (about 1e-4 of its range for a
// period that is not a whole number of samples); a wrong period spreads it by tens of percent.
constexpr double kReferenceSpread = 0.01;
// A measured position's noise is far below its motion in any identification run.
constexpr double kPositionSpread = 0.1;
// A column whose whole range is within this many of its sample-to-sample noise σ does not move:
// the range of up to 10⁷ samples of white Gaussian noise is about 10.4 σ.
constexpr double kNoiseRange = 12.0;

// The sample-to-sample noise σ of a column, whatever the period: RMS of its second differences
// over √6 (white noise of std σ gives σ√6; a motion sampled at ω adds only (ω·Ts)² of its
// amplitude). 0 for fewer than 3 samples.
double difference_noise_std(const Eigen::Ref<const Eigen::VectorXd>& x) {
  const Eigen::Index m = x.size();
  if (m < 3) return 0.0;
  const Eigen::VectorXd d2 = x.tail(m - 2) - 2.0 * x.segment(1, m - 2) + x.head(m - 2);
  return std::sqrt(d2.squaredNorm() / static_cast<double>(m - 2) / 6.0);
}

}  // namespace

double averaged_noise_std(double raw_std, int periods, const PeriodicLowpassOptions* lowpass) {
  if (!std::isfinite(raw_std) || raw_std < 0.0 || periods < 1)
    throw Error("averaged_noise_std: needs a finite std >= 0 and periods >= 1, got " +
                short_number(raw_std) + " and " + std::to_string(periods));
  double gamma = 1.0, decimate = 1.0;
  if (lowpass) {
    if (lowpass->decimate < 1)
      throw Error("averaged_noise_std: decimation must be >= 1, got " +
                  std::to_string(lowpass->decimate));
    decimate = lowpass->decimate;
    // Mean of |H|⁴ over the pass band by the midpoint rule: the ripple of an order-8 Chebyshev
    // has 4 cycles there, 400 points resolve it far below the 1e-3 this is good for.
    const SosFilter h = design_lowpass_unit_dc(lowpass->design);
    constexpr int kPoints = 400;
    gamma = 0.0;
    for (int i = 0; i < kPoints; ++i) {
      const double f = lowpass->design.cutoff_hz * (i + 0.5) / kPoints;
      gamma += std::pow(std::norm(frequency_response(h, f, lowpass->design.sample_rate_hz)), 2) /
               kPoints;
    }
  }
  return raw_std * std::sqrt(gamma / (static_cast<double>(periods) * decimate));
}

bool is_reference_channel(const std::string& name) {
  for (const char* prefix : {"qr", "dqr", "ddqr"})
    if (has_index_suffix(name, prefix)) return true;
  return false;
}

std::vector<std::string> check_period_repeats(const TimedPeriodAverage& a,
                                              const Eigen::Ref<const Eigen::MatrixXd>& x,
                                              const std::vector<std::string>& names) {
  if (x.cols() != static_cast<Eigen::Index>(names.size()) || a.channels.size() != names.size() ||
      x.rows() < 2)
    throw Error("check_period_repeats: sizes of the data, names and average do not match");
  const double period = a.samples_per_period * a.sample_time;
  std::vector<std::string> warnings;
  for (std::size_t c = 0; c < names.size(); ++c) {
    const auto col = x.col(static_cast<Eigen::Index>(c));
    const double range = col.maxCoeff() - col.minCoeff();
    if (!(range > 0.0)) continue;  // a held joint repeats with any period
    const double spread = a.channels[c].std / range;
    if (is_reference_channel(names[c]) && spread > kReferenceSpread) {
      std::string own;
      try {
        own = "; its own period is " + short_number(detect_period(col) * a.sample_time) +
              " s (autocorrelation)";
      } catch (const Error&) {
        own = "; no period found in it (is it periodic?)";
      }
      throw Error("the reference " + names[c] + " does not repeat with the period " +
                  short_number(period) + " s: its periods differ by " +
                  short_number(100.0 * spread) +
                  " % of its range (a noise-free reference "
                  "repeats to its interpolation error)" +
                  own + "; check --period/--f0");
    }
    // A held joint's range is its noise: its spread is a large part of it whatever the period
    // (a wrong period cannot smear a constant), so it says nothing about the period.
    if (has_index_suffix(names[c], "q") && spread > kPositionSpread &&
        range > kNoiseRange * difference_noise_std(col))
      warnings.push_back(names[c] + " spreads by " + short_number(100.0 * spread) +
                         " % of its range across the periods of " + short_number(period) +
                         " s: the noise statistics and the mean period are doubtful (noise, "
                         "drift, or not the period of the run: check --period/--f0)");
  }
  return warnings;
}

}  // namespace dynid
