#include "dynid/signal/resampling.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/signal/lowpass_design.hpp"
#include "dynid/signal/sampling_check.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

namespace dynid {

namespace {

// Second derivatives M (m × n) of the natural cubic spline through (t, x): tridiagonal system
// h_{i−1}M_{i−1} + 2(h_{i−1}+h_i)M_i + h_i M_{i+1} = 6(Δ_i − Δ_{i−1}), M_0 = M_{m−1} = 0,
// solved by the Thomas algorithm for all columns at once.
Eigen::MatrixXd spline_second_derivatives(const Eigen::Ref<const Eigen::VectorXd>& t,
                                          const Eigen::Ref<const Eigen::MatrixXd>& x) {
  const Eigen::Index m = t.size();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(m, x.cols());
  if (m < 3) return M;
  Eigen::VectorXd c(m);  // modified super-diagonal
  for (Eigen::Index i = 1; i < m - 1; ++i) {
    const double h0 = t(i) - t(i - 1), h1 = t(i + 1) - t(i);
    const double diag = 2.0 * (h0 + h1) - (i > 1 ? h0 * c(i - 1) : 0.0);
    M.row(i) = 6.0 * ((x.row(i + 1) - x.row(i)) / h1 - (x.row(i) - x.row(i - 1)) / h0);
    if (i > 1) M.row(i) -= h0 * M.row(i - 1);
    M.row(i) /= diag;
    c(i) = h1 / diag;
  }
  for (Eigen::Index i = m - 3; i >= 1; --i) M.row(i) -= c(i) * M.row(i + 1);
  return M;
}

Eigen::VectorXd uniform_grid(double t0, double t_end, double rate_hz) {
  const auto count = static_cast<Eigen::Index>(std::floor((t_end - t0) * rate_hz + 1e-9)) + 1;
  Eigen::VectorXd g(count);
  for (Eigen::Index k = 0; k < count; ++k) g(k) = t0 + static_cast<double>(k) / rate_hz;
  g(count - 1) = std::min(g(count - 1), t_end);  // guard rounding at the last point
  return g;
}

LowpassOptions anti_alias_design(const AntiAliasOptions& a, double new_rate, double data_rate) {
  LowpassOptions lp;
  lp.family = LowpassFamily::kChebyshev1;
  lp.order = a.order;
  lp.ripple_db = a.ripple_db;
  lp.cutoff_hz = a.cutoff_fraction * 0.5 * new_rate;
  lp.sample_rate_hz = data_rate;
  return lp;
}

}  // namespace

Eigen::MatrixXd interpolate(const Eigen::Ref<const Eigen::VectorXd>& t,
                            const Eigen::Ref<const Eigen::MatrixXd>& x,
                            const Eigen::Ref<const Eigen::VectorXd>& tq, Interpolation method) {
  check_time_rows("interpolation", t, x);
  check_sampling(t);
  const Eigen::Index m = t.size();
  for (Eigen::Index q = 0; q < tq.size(); ++q) {
    if (!(tq(q) >= t(0) && tq(q) <= t(m - 1))) {
      std::ostringstream msg;
      msg.precision(17);
      msg << "interpolation query " << q << " at t = " << tq(q) << " is outside the data [" << t(0)
          << ", " << t(m - 1) << "] s: query only inside the recorded time span";
      throw Error(msg.str());
    }
  }
  const Eigen::MatrixXd M =
      method == Interpolation::kCubicSpline ? spline_second_derivatives(t, x) : Eigen::MatrixXd();
  Eigen::MatrixXd y(tq.size(), x.cols());
  for (Eigen::Index q = 0; q < tq.size(); ++q) {
    // Interval i with t_i ≤ tq < t_{i+1} (the last interval for tq = t_{m−1}).
    Eigen::Index i = std::upper_bound(t.data(), t.data() + m, tq(q)) - t.data() - 1;
    i = std::clamp<Eigen::Index>(i, 0, m - 2);
    const double h = t(i + 1) - t(i), a = (t(i + 1) - tq(q)) / h, b = (tq(q) - t(i)) / h;
    y.row(q) = a * x.row(i) + b * x.row(i + 1);
    if (method == Interpolation::kCubicSpline) {
      y.row(q) += (h * h / 6.0) * ((a * a * a - a) * M.row(i) + (b * b * b - b) * M.row(i + 1));
    }
  }
  return y;
}

UniformRecord decimate(const Eigen::Ref<const Eigen::VectorXd>& t,
                       const Eigen::Ref<const Eigen::MatrixXd>& x, int factor,
                       const AntiAliasOptions& anti_alias, double uniform_tolerance) {
  if (factor < 1) {
    throw Error("decimation factor is " + std::to_string(factor) +
                ": give an integer factor of at least 1");
  }
  check_time_rows("decimation", t, x);
  const SamplingInfo info = require_uniform_sampling(t, uniform_tolerance, "decimation");
  Eigen::MatrixXd filtered;
  if (factor > 1 && anti_alias.enabled) {
    filtered =
        lowpass_filtfilt(anti_alias_design(anti_alias, info.rate_hz() / factor, info.rate_hz()), x);
  } else {
    filtered = x;
  }
  const Eigen::Index count = (t.size() + factor - 1) / factor;
  UniformRecord out;
  out.t.resize(count);
  out.x.resize(count, x.cols());
  for (Eigen::Index k = 0; k < count; ++k) {
    out.t(k) = t(k * factor);
    out.x.row(k) = filtered.row(k * factor);
  }
  return out;
}

UniformRecord resample_uniform(const Eigen::Ref<const Eigen::VectorXd>& t,
                               const Eigen::Ref<const Eigen::MatrixXd>& x, double rate_hz,
                               const ResampleOptions& options) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) {
    std::ostringstream msg;
    msg << "resampling rate is " << rate_hz << " Hz: give a positive target sample rate";
    throw Error(msg.str());
  }
  check_time_rows("resampling", t, x);
  const SamplingInfo info = check_sampling(t);
  const Eigen::Index m = t.size();
  UniformRecord out;
  out.t = uniform_grid(t(0), t(m - 1), rate_hz);
  if (options.anti_alias.enabled && rate_hz < info.rate_hz() * (1.0 - 1e-9)) {
    // Uniform grid at the data's own mean rate (same number of samples), then zero-phase low-pass.
    Eigen::VectorXd tu = Eigen::VectorXd::LinSpaced(m, t(0), t(m - 1));
    const Eigen::MatrixXd xu = interpolate(t, x, tu, options.interpolation);
    const Eigen::MatrixXd xf =
        lowpass_filtfilt(anti_alias_design(options.anti_alias, rate_hz, info.rate_hz()), xu);
    out.x = interpolate(tu, xf, out.t, options.interpolation);
  } else {
    out.x = interpolate(t, x, out.t, options.interpolation);
  }
  return out;
}

}  // namespace dynid
