#include "dynid/sim/error_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"

namespace dynid {

double kolmogorov_survival(double lambda) {
  if (lambda <= 0.0) return 1.0;
  // Q_KS(λ) = 2 Σ (−1)^{k−1} exp(−2k²λ²); the alternating series converges fast for λ ≳ 0.3. For
  // small λ use the dual form 1 − (√(2π)/λ) Σ exp(−(2k−1)²π²/(8λ²)) (Jacobi theta identity).
  constexpr double kPi = 3.14159265358979323846;
  if (lambda < 1.0) {
    double sum = 0.0;
    for (int k = 1; k <= 50; ++k) {
      const double a = (2.0 * k - 1.0) * kPi / lambda;
      sum += std::exp(-a * a / 8.0);
    }
    return std::clamp(1.0 - std::sqrt(2.0 * kPi) / lambda * sum, 0.0, 1.0);
  }
  double sum = 0.0, sign = 1.0;
  for (int k = 1; k <= 100; ++k) {
    const double term = std::exp(-2.0 * k * k * lambda * lambda);
    sum += sign * term;
    if (term < 1e-17) break;
    sign = -sign;
  }
  return std::clamp(2.0 * sum, 0.0, 1.0);
}

ErrorStatistics error_statistics(const Eigen::Ref<const Eigen::VectorXd>& e) {
  const long n = e.size();
  if (n < 2) throw Error("error statistics need at least 2 samples, got " + std::to_string(n));
  if (!e.allFinite()) throw Error("error signal has NaN or Inf values: check the input data");
  ErrorStatistics s;
  s.samples = n;
  s.rms = std::sqrt(e.squaredNorm() / n);
  s.max_abs = e.cwiseAbs().maxCoeff();
  s.mean = e.mean();
  double m2 = 0.0, m3 = 0.0, m4 = 0.0;
  for (long i = 0; i < n; ++i) {
    const double d = e[i] - s.mean, d2 = d * d;
    m2 += d2;
    m3 += d2 * d;
    m4 += d2 * d2;
  }
  m2 /= n;
  m3 /= n;
  m4 /= n;
  s.std = std::sqrt(m2);
  if (!(s.std > 1e-300) || s.std <= 1e-14 * std::abs(s.mean)) {
    s.std = 0.0;
    s.ks_statistic = 1.0;
    s.ks_p_value = 0.0;
    return s;
  }
  s.skewness = m3 / (m2 * s.std);
  s.kurtosis = m4 / (m2 * m2);
  std::vector<double> sorted(e.data(), e.data() + n);
  std::sort(sorted.begin(), sorted.end());
  double d_max = 0.0;
  for (long i = 0; i < n; ++i) {
    const double phi = 0.5 * std::erfc(-(sorted[i] - s.mean) / (s.std * std::sqrt(2.0)));
    d_max =
        std::max({d_max, phi - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - phi});
  }
  s.ks_statistic = d_max;
  const double sn = std::sqrt(static_cast<double>(n));
  s.ks_p_value = kolmogorov_survival((sn + 0.12 + 0.11 / sn) * d_max);  // Stephens (1970)
  return s;
}

ErrorHistogram error_histogram(const Eigen::Ref<const Eigen::VectorXd>& e, int bins) {
  if (bins < 1) throw Error("a histogram needs at least 1 bin, got " + std::to_string(bins));
  const ErrorStatistics stats = error_statistics(e);  // checks size and finiteness
  double lo = e.minCoeff(), hi = e.maxCoeff();
  if (hi - lo <= 0.0) {
    lo -= 0.5;
    hi += 0.5;
  }
  const double width = (hi - lo) / bins;
  ErrorHistogram h;
  h.center.resize(bins);
  h.density = Eigen::VectorXd::Zero(bins);
  h.gaussian = Eigen::VectorXd::Zero(bins);
  for (Eigen::Index k = 0; k < e.size(); ++k) {
    const int b = std::clamp(static_cast<int>((e[k] - lo) / width), 0, bins - 1);
    h.density[b] += 1.0;
  }
  h.density /= static_cast<double>(e.size()) * width;
  constexpr double kPi = 3.14159265358979323846;
  for (int b = 0; b < bins; ++b) {
    h.center[b] = lo + (b + 0.5) * width;
    if (stats.std > 0.0) {
      const double z = (h.center[b] - stats.mean) / stats.std;
      h.gaussian[b] = std::exp(-0.5 * z * z) / (stats.std * std::sqrt(2.0 * kPi));
    }
  }
  return h;
}

}  // namespace dynid
