#include "dynid/signal/periodic_filter.hpp"

#include <unsupported/Eigen/FFT>

#include <complex>
#include <cstdlib>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

namespace dynid {
namespace {

// Rows 0, n, 2n, … of x (n divides x.rows(), checked by the caller).
Eigen::MatrixXd every_nth_row(const Eigen::Ref<const Eigen::MatrixXd>& x, int n) {
  Eigen::MatrixXd out(x.rows() / n, x.cols());
  for (Eigen::Index k = 0; k < out.rows(); ++k) out.row(k) = x.row(k * n);
  return out;
}

}  // namespace

Eigen::MatrixXd filtfilt_periodic(const SosFilter& filter,
                                  const Eigen::Ref<const Eigen::MatrixXd>& x) {
  const Eigen::Index p = x.rows();
  if (p < 2)
    throw Error("periodic filter: one period needs at least 2 samples, got " + std::to_string(p));
  if (!x.allFinite()) throw Error("periodic filter: the period contains NaN or Inf");
  // |H|² per bin: the forward and the backward pass of filtfilt, in steady state on a periodic
  // input, multiply each line by H and by conj(H).
  std::vector<double> gain(static_cast<size_t>(p));
  for (Eigen::Index b = 0; b < p; ++b) {
    const double cycles = static_cast<double>(b <= p / 2 ? b : p - b) / static_cast<double>(p);
    gain[static_cast<size_t>(b)] = std::norm(frequency_response(filter, cycles, 1.0));
  }
  Eigen::FFT<double> fft;
  Eigen::MatrixXd out(p, x.cols());
  std::vector<double> column(static_cast<size_t>(p)), back;
  std::vector<std::complex<double>> f;
  for (Eigen::Index c = 0; c < x.cols(); ++c) {
    for (Eigen::Index k = 0; k < p; ++k) column[static_cast<size_t>(k)] = x(k, c);
    fft.fwd(f, column);
    for (size_t b = 0; b < f.size(); ++b) f[b] *= gain[b];
    fft.inv(back, f);
    for (Eigen::Index k = 0; k < p; ++k) out(k, c) = back[static_cast<size_t>(k)];
  }
  return out;
}

Eigen::MatrixXd lowpass_periodic(const PeriodicLowpassOptions& options,
                                 const Eigen::Ref<const Eigen::MatrixXd>& x) {
  const Eigen::Index p = x.rows();
  const int n = options.decimate;
  if (n < 1) throw Error("decimation factor must be >= 1, got " + std::to_string(n));
  if (p % n != 0) {
    std::string divisors;
    for (Eigen::Index d = 2; d <= std::min<Eigen::Index>(p / 2, 50); ++d)
      if (p % d == 0) divisors += (divisors.empty() ? "" : ", ") + std::to_string(d);
    throw Error("decimation by " + std::to_string(n) + " does not divide the period's " +
                std::to_string(p) +
                " samples: the kept samples would not be evenly spaced across the period's "
                "wrap; use a factor that divides it (" +
                (divisors.empty() ? std::string("none up to 50") : divisors) + ")");
  }
  if (p / n < 2)
    throw Error("decimation by " + std::to_string(n) + " leaves " + std::to_string(p / n) +
                " sample(s) of the period's " + std::to_string(p) + "; use a smaller factor");
  const double nyquist = options.design.sample_rate_hz / (2.0 * n);
  if (n > 1 && !(options.design.cutoff_hz < nyquist))
    throw Error("cut-off " + short_number(options.design.cutoff_hz) +
                " Hz is not below the decimated Nyquist rate " + short_number(nyquist) +
                " Hz (rate " + short_number(options.design.sample_rate_hz) + " Hz / (2 x " +
                std::to_string(n) +
                ")): the decimation would alias; lower the cut-off or the decimation factor");
  return every_nth_row(filtfilt_periodic(design_lowpass_unit_dc(options.design), x), n);
}

LowpassedPeriod lowpass_period_columns(const PeriodicLowpassOptions& options,
                                       const Eigen::Ref<const Eigen::VectorXd>& phase,
                                       const Eigen::Ref<const Eigen::MatrixXd>& x,
                                       const std::vector<Eigen::Index>& filtered) {
  if (phase.size() != x.rows())
    throw Error("periodic filter: " + std::to_string(phase.size()) + " phase times for " +
                std::to_string(x.rows()) + " rows");
  Eigen::MatrixXd selected(x.rows(), static_cast<Eigen::Index>(filtered.size()));
  for (std::size_t c = 0; c < filtered.size(); ++c) {
    if (filtered[c] < 0 || filtered[c] >= x.cols())
      throw Error("periodic filter: column " + std::to_string(filtered[c]) + " outside the " +
                  std::to_string(x.cols()) + " columns");
    selected.col(static_cast<Eigen::Index>(c)) = x.col(filtered[c]);
  }
  const Eigen::MatrixXd low = lowpass_periodic(options, selected);  // checks N against P
  LowpassedPeriod out;
  out.phase = every_nth_row(phase, options.decimate);
  out.x = every_nth_row(x, options.decimate);
  for (std::size_t c = 0; c < filtered.size(); ++c)
    out.x.col(filtered[c]) = low.col(static_cast<Eigen::Index>(c));
  return out;
}

}  // namespace dynid
