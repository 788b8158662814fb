#pragma once

#include <Eigen/Core>

namespace dynid {

/// Three-point finite differences on the actual (possibly non-uniform) time stamps, column-wise.
/// Each sample's derivative is that of the quadratic through three neighbouring samples: the
/// centred points (k−1, k, k+1) inside, the one-sided points (0, 1, 2) and (m−3, m−2, m−1) at the
/// ends (second-order accurate there too). With h1 = t_k − t_{k−1}, h2 = t_{k+1} − t_k:
///   x'_k  = −h2/(h1(h1+h2))·x_{k−1} + (h2−h1)/(h1h2)·x_k + h1/(h2(h1+h2))·x_{k+1}
///   x''_k = 2·(h2·x_{k−1} − (h1+h2)·x_k + h1·x_{k+1})/(h1h2(h1+h2)).
/// Identity: exact for polynomials of degree ≤ 2 (derivative 1 and 2). Seed 1 (Dutkiewicz,
/// Kozłowski) differentiates positions with such a 3-point filter (Δt = 32 ms).
/// t: m seconds, x: m × n; returns m × n in units of x per s^derivative.
/// Throws dynid::Error if derivative is not 1 or 2, sizes differ, m < 3, or t is not strictly
/// increasing (check_sampling).
Eigen::MatrixXd central_difference(const Eigen::Ref<const Eigen::VectorXd>& t,
                                   const Eigen::Ref<const Eigen::MatrixXd>& x, int derivative = 1);

/// Savitzky–Golay smoothing / differentiation in actual time.
struct SavitzkyGolayOptions {
  int window = 11;     ///< samples in the moving window, odd, > order; shifted inward at the ends
  int order = 3;       ///< degree of the local polynomial, ≥ derivative
  int derivative = 1;  ///< 0 = smoothed value, 1 = first, 2 = second derivative
};

/// Savitzky–Golay filter on non-uniform time: for every sample k, fits by least squares a
/// polynomial of degree `order` in (t − t_k) to the `window` samples centred on k (the window is
/// shifted to stay inside the data at the ends) and returns its value or derivative at t_k.
/// Identity: exact for polynomials of degree ≤ order. t: m seconds, x: m × n; returns m × n.
/// The fit weights depend on t only, so they are computed once per sample for all columns.
/// Throws dynid::Error for an even window, window ≤ order, derivative outside 0..2 or > order,
/// window > m, size mismatch, or non-increasing t.
Eigen::MatrixXd savitzky_golay(const Eigen::Ref<const Eigen::VectorXd>& t,
                               const Eigen::Ref<const Eigen::MatrixXd>& x,
                               const SavitzkyGolayOptions& options = {});

}  // namespace dynid
