#pragma once

#include <Eigen/Core>

namespace dynid {

/// Interpolation used to evaluate sampled data between its time stamps.
enum class Interpolation {
  kLinear,       ///< piecewise linear (exact for straight lines, never overshoots)
  kCubicSpline,  ///< natural cubic spline, C² (zero second derivative at both ends)
};

/// Evaluates the columns of x (m × n, sampled at strictly increasing t, seconds) at the query times
/// tq (any order, each within [t_0, t_{m−1}]). Linear: exact for degree ≤ 1. Natural cubic spline:
/// interpolates the samples, exact for degree ≤ 1, error ≤ 5/384·h_max⁴·max|x⁗| away from the
/// ends (Hall & Meyer 1976). Returns tq.size() × n.
/// Throws dynid::Error on size mismatch, fewer than 2 samples, bad t, or a query outside the data
/// (naming the first such query index).
Eigen::MatrixXd interpolate(const Eigen::Ref<const Eigen::VectorXd>& t,
                            const Eigen::Ref<const Eigen::MatrixXd>& x,
                            const Eigen::Ref<const Eigen::VectorXd>& tq,
                            Interpolation method = Interpolation::kCubicSpline);

/// A uniformly sampled record: time stamps and the samples (rows) at them.
struct UniformRecord {
  Eigen::VectorXd t;  ///< m time stamps [s], uniform
  Eigen::MatrixXd x;  ///< m × n samples
};

/// Anti-alias filter used before reducing the sample rate.
struct AntiAliasOptions {
  bool enabled = true;           ///< low-pass before reducing the rate (turn off only to compare)
  int order = 8;                 ///< Chebyshev I order (seed 2 §3.4 uses 8)
  double ripple_db = 0.05;       ///< passband ripple [dB]
  double cutoff_fraction = 0.8;  ///< cut-off as a fraction of the NEW Nyquist rate (scipy default)
};

/// Decimation by an integer factor q: zero-phase Chebyshev I low-pass at
/// cutoff_fraction·fs/(2q), then keeps rows 0, q, 2q, … (and their time stamps).
/// t must be uniform within uniform_tolerance (relative step deviation). q = 1 returns a copy.
/// Throws dynid::Error for q < 1, non-uniform or bad t, size mismatch, or too few samples for the
/// filter padding.
UniformRecord decimate(const Eigen::Ref<const Eigen::VectorXd>& t,
                       const Eigen::Ref<const Eigen::MatrixXd>& x, int factor,
                       const AntiAliasOptions& anti_alias = {}, double uniform_tolerance = 1e-3);

/// Options of resample_uniform.
struct ResampleOptions {
  Interpolation interpolation = Interpolation::kCubicSpline;  ///< between the samples
  AntiAliasOptions anti_alias;  ///< applied only when rate_hz is below the data's mean rate
};

/// Resamples (possibly non-uniform) data onto the uniform grid t_k = t_0 + k/rate_hz,
/// k = 0 … ⌊(t_{m−1} − t_0)·rate_hz⌋. When downsampling (rate_hz < the mean rate of t) and the
/// anti-alias filter is enabled, the data are first interpolated onto a uniform grid at their mean
/// rate, low-pass filtered (zero phase) at cutoff_fraction·rate_hz/2, then interpolated onto the
/// target grid (seed 2 §3.4: filter, then resample at 200 Hz).
/// Throws dynid::Error for rate_hz ≤ 0, bad t, size mismatch, or too few samples.
UniformRecord resample_uniform(const Eigen::Ref<const Eigen::VectorXd>& t,
                               const Eigen::Ref<const Eigen::MatrixXd>& x, double rate_hz,
                               const ResampleOptions& options = {});

}  // namespace dynid
