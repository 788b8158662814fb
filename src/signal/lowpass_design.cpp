#include "dynid/signal/lowpass_design.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "dynid/common/error.hpp"

namespace dynid {

namespace {

constexpr double kPi = 3.14159265358979323846;

void check_options(const LowpassOptions& o) {
  if (o.order < 1) {
    throw Error("low-pass filter order is " + std::to_string(o.order) +
                ": give an order of at least 1");
  }
  if (!(o.sample_rate_hz > 0.0) || !std::isfinite(o.sample_rate_hz)) {
    std::ostringstream msg;
    msg << "low-pass filter sample rate is " << o.sample_rate_hz
        << " Hz: give the positive sample rate of the data";
    throw Error(msg.str());
  }
  const double nyquist = 0.5 * o.sample_rate_hz;
  if (!(o.cutoff_hz > 0.0) || !(o.cutoff_hz < nyquist)) {
    std::ostringstream msg;
    msg << "low-pass cut-off " << o.cutoff_hz << " Hz is outside (0, Nyquist = " << nyquist
        << " Hz) for sample rate " << o.sample_rate_hz
        << " Hz: lower the cut-off or use data sampled faster";
    throw Error(msg.str());
  }
  if (o.family == LowpassFamily::kChebyshev1 &&
      !(o.ripple_db > 0.0 && std::isfinite(o.ripple_db))) {
    std::ostringstream msg;
    msg << "Chebyshev passband ripple is " << o.ripple_db
        << " dB: give a positive ripple (e.g. 0.5 dB)";
    throw Error(msg.str());
  }
}

}  // namespace

int SosFilter::order() const {
  int n = 0;
  for (int s = 0; s < sections(); ++s) n += (sos(s, 2) == 0.0 && sos(s, 5) == 0.0) ? 1 : 2;
  return n;
}

SosFilter design_lowpass(const LowpassOptions& options) {
  check_options(options);
  const int n = options.order;
  const double fs = options.sample_rate_hz;
  // Pre-warped analog cut-off so that the digital cut-off lands exactly on fc.
  const double wc = 2.0 * fs * std::tan(kPi * options.cutoff_hz / fs);

  // Analog prototype poles in the upper half plane (plus the real one for odd order), scaled by wc.
  std::vector<std::complex<double>> poles;  // one per conjugate pair, or the real pole
  double dc_gain = 1.0;
  if (options.family == LowpassFamily::kButterworth) {
    for (int k = 1; k <= n; ++k) {
      const std::complex<double> p = std::polar(1.0, kPi * (2.0 * k + n - 1.0) / (2.0 * n));
      if (p.imag() >= -1e-14) poles.push_back(wc * p);
    }
  } else {
    const double eps = std::sqrt(std::pow(10.0, options.ripple_db / 10.0) - 1.0);
    const double mu = std::asinh(1.0 / eps) / n;
    for (int k = 1; k <= n; ++k) {
      const double theta = kPi * (2.0 * k - 1.0) / (2.0 * n);
      const std::complex<double> p(-std::sinh(mu) * std::sin(theta),
                                   std::cosh(mu) * std::cos(theta));
      if (p.imag() >= -1e-14) poles.push_back(wc * p);
    }
    if (n % 2 == 0) dc_gain = 1.0 / std::sqrt(1.0 + eps * eps);
  }
  // Sections with poles far from the unit circle first, the sharpest (highest Q) last.
  std::sort(poles.begin(), poles.end(), [](const auto& a, const auto& b) {
    return std::abs(a.real()) / std::abs(a) > std::abs(b.real()) / std::abs(b);
  });

  SosFilter filter;
  filter.sos.resize(static_cast<Eigen::Index>(poles.size()), 6);
  const double k2 = 2.0 * fs;
  for (std::size_t s = 0; s < poles.size(); ++s) {
    const std::complex<double> z = (k2 + poles[s]) / (k2 - poles[s]);  // bilinear transform
    const auto r = static_cast<Eigen::Index>(s);
    if (std::abs(poles[s].imag()) <= 1e-12 * std::abs(poles[s])) {
      // Real pole: first-order section (1 + z⁻¹)/(1 − z_p z⁻¹), unit DC gain.
      const double a1 = -z.real();
      const double g = (1.0 + a1) / 2.0;
      filter.sos.row(r) << g, g, 0.0, 1.0, a1, 0.0;
    } else {
      // Conjugate pair: zeros at −1 (double), poles z, z*; unit DC gain.
      const double a1 = -2.0 * z.real();
      const double a2 = std::norm(z);
      const double g = (1.0 + a1 + a2) / 4.0;
      filter.sos.row(r) << g, 2.0 * g, g, 1.0, a1, a2;
    }
  }
  filter.sos.row(0).head<3>() *= dc_gain;
  return filter;
}

std::complex<double> frequency_response(const SosFilter& filter, double frequency_hz,
                                        double sample_rate_hz) {
  const std::complex<double> zi = std::polar(1.0, -2.0 * kPi * frequency_hz / sample_rate_hz);
  const std::complex<double> zi2 = zi * zi;
  std::complex<double> h(1.0, 0.0);
  for (int s = 0; s < filter.sections(); ++s) {
    const auto& c = filter.sos.row(s);
    h *= (c(0) + c(1) * zi + c(2) * zi2) / (c(3) + c(4) * zi + c(5) * zi2);
  }
  return h;
}

SosFilter design_lowpass_unit_dc(const LowpassOptions& options) {
  SosFilter filter = design_lowpass(options);
  double dc = 1.0;
  for (int k = 0; k < filter.sections(); ++k) {
    const auto row = filter.sos.row(k);
    dc *= (row(0) + row(1) + row(2)) / (row(3) + row(4) + row(5));
  }
  filter.sos.row(0).head<3>() /= dc;
  return filter;
}

}  // namespace dynid
