#include "dynid/signal/noise_floor.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <iomanip>
#include <sstream>
#include <vector>

#include <unsupported/Eigen/FFT>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

namespace dynid {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr Eigen::Index kMinSamples = 129;

void check_rate(double rate_hz) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    throw Error("sample rate " + short_number(rate_hz) + " Hz is not > 0; pass the data's rate");
  }
}

// Level R_k = P_k/|1 − e^{−iω_k}|² of the differenced column for k = 1 … N/2 (index k − 1).
Eigen::VectorXd whitened_level(const Eigen::VectorXd& x, int max_segment, int& segment) {
  const Eigen::Index m = x.size() - 1;
  int N = 64;
  while (2 * N <= std::min<Eigen::Index>(m, max_segment)) N *= 2;
  segment = N;
  Eigen::VectorXd w(N);
  // 4-term Blackman–Harris (sidelobes −92 dB): a large slow motion must not leak onto the floor.
  for (int i = 0; i < N; ++i) {
    const double x = 2.0 * kPi * i / N;
    w[i] = 0.35875 - 0.48829 * std::cos(x) + 0.14128 * std::cos(2 * x) - 0.01168 * std::cos(3 * x);
  }
  const double U = w.squaredNorm();
  const Eigen::VectorXd d = x.tail(m) - x.head(m);
  Eigen::FFT<double> fft;
  std::vector<double> in(N);
  std::vector<std::complex<double>> out;
  Eigen::VectorXd acc = Eigen::VectorXd::Zero(N / 2);
  int count = 0;
  for (Eigen::Index start = 0; start + N <= m; start += N / 2, ++count) {
    const double mean = d.segment(start, N).mean();
    for (int i = 0; i < N; ++i) in[i] = w[i] * (d[start + i] - mean);
    fft.fwd(out, in);
    for (int k = 1; k <= N / 2; ++k) acc[k - 1] += std::norm(out[k]);
  }
  for (int k = 1; k <= N / 2; ++k) {
    acc[k - 1] /= count * U * 2.0 * (1.0 - std::cos(2.0 * kPi * k / N));
  }
  return acc;
}

}  // namespace

NoiseFloor position_noise_floor(const Eigen::Ref<const Eigen::MatrixXd>& q, double rate_hz,
                                const NoiseFloorOptions& options) {
  check_rate(rate_hz);
  const Eigen::Index n = q.cols();
  NoiseFloor out;
  out.noise_std = Eigen::VectorXd::Constant(n, NAN);
  out.signal_edge_hz = Eigen::VectorXd::Constant(n, NAN);
  if (q.rows() < kMinSamples) return out;
  for (Eigen::Index j = 0; j < n; ++j) {
    int N = 0;
    const Eigen::VectorXd R = whitened_level(q.col(j), options.max_segment, N);
    // One-third-octave bands of bins (at least one bin each).
    std::vector<double> level, centre;
    for (int lo = 1; lo <= N / 2;) {
      const int hi = std::min(N / 2, std::max(lo, static_cast<int>(std::floor(lo * 1.26))));
      level.push_back(R.segment(lo - 1, hi - lo + 1).mean());
      centre.push_back(0.5 * (lo + hi) * rate_hz / N);
      lo = hi + 1;
    }
    std::vector<double> high;
    for (size_t b = 0; b < level.size(); ++b) {
      if (centre[b] > 0.25 * rate_hz) high.push_back(level[b]);
    }
    std::nth_element(high.begin(), high.begin() + high.size() / 2, high.end());
    const double floor = high[high.size() / 2];
    out.noise_std[j] = std::sqrt(floor);
    // The motion's band is contiguous from the lowest frequencies; a narrow peak beyond an octave
    // of floor (a control-loop resonance driven by the noise fed back) is not motion to identify.
    double edge = 0.0, quiet_since = 0.0;
    for (size_t b = 0; b < level.size() && centre[b] <= 0.25 * rate_hz; ++b) {
      if (level[b] >= options.signal_to_noise * floor) {
        edge = centre[b];
        quiet_since = 0.0;
      } else if (quiet_since == 0.0) {
        quiet_since = centre[b];
      } else if (edge > 0.0 && centre[b] >= 2.0 * quiet_since) {
        break;
      }
    }
    out.signal_edge_hz[j] = edge;
  }
  return out;
}

CutoffChoice choose_cutoff(const Eigen::Ref<const Eigen::MatrixXd>& q, double rate_hz,
                           const CutoffRule& rule) {
  check_rate(rate_hz);
  CutoffChoice c;
  c.floor = position_noise_floor(q, rate_hz, rule.noise);
  const double hi = std::min(rule.max_hz, rule.max_fraction_of_rate * rate_hz);
  const double lo = std::min(rule.min_hz, hi);
  std::ostringstream s;
  s << std::setprecision(3);
  if (!c.floor.signal_edge_hz.allFinite() || c.floor.signal_edge_hz.size() == 0) {
    c.cutoff_hz = hi;
    s << "auto: " << c.cutoff_hz << " Hz, the upper bound (too few samples for a spectrum)";
    c.reason = s.str();
    return c;
  }
  const double edge = c.floor.signal_edge_hz.maxCoeff();
  c.cutoff_hz = std::clamp(rule.margin * edge, lo, hi);
  s << "auto: " << c.cutoff_hz << " Hz = " << rule.margin
    << " x the highest frequency where a position spectrum stands " << rule.noise.signal_to_noise
    << "x above its white-noise floor (" << edge << " Hz; noise std up to "
    << c.floor.noise_std.maxCoeff() << "), within [" << lo << ", " << hi << "] Hz";
  if (c.cutoff_hz == hi && rule.margin * edge > hi) s << " (upper bound)";
  if (c.cutoff_hz == lo && rule.margin * edge < lo) s << " (lower bound)";
  c.reason = s.str();
  return c;
}

double white_noise_gain(const SosFilter* filter, int derivative, double rate_hz) {
  check_rate(rate_hz);
  if (derivative < 0 || derivative > 2) {
    throw Error("white_noise_gain: derivative " + std::to_string(derivative) + " is not 0, 1 or 2");
  }
  // Long enough for the impulse response of a cut-off down to ~rate/2000 to decay.
  const Eigen::Index half = 8192;
  Eigen::MatrixXd h = Eigen::MatrixXd::Zero(2 * half + 1, 1);
  h(half, 0) = 1.0;
  if (filter != nullptr) h = filtfilt(*filter, h);
  // Central differences applied `derivative` times, as preprocess() derives q̇ and then q̈.
  for (int d = 0; d < derivative; ++d) {
    Eigen::MatrixXd dh = Eigen::MatrixXd::Zero(h.rows(), 1);
    for (Eigen::Index k = 1; k + 1 < h.rows(); ++k)
      dh(k, 0) = 0.5 * rate_hz * (h(k + 1, 0) - h(k - 1, 0));
    h = std::move(dh);
  }
  return h.norm();
}

}  // namespace dynid
