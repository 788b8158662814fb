#pragma once

#include <Eigen/Core>

#include "dynid/identification/record.hpp"

namespace dynid::detail {

/// Asymmetric friction columns of joint j at sample k of a prepared run (seed 2 eq. 2,
/// docs/design.md §3 order Fvp Fvn Fcp Fcn): q̇·[q̇>0], q̇·[q̇<0], then the Coulomb halves — the
/// filtered expected sign when the run carries it (preprocess(), parallel filtering), else the
/// indicators.
inline Eigen::Vector4d friction_columns(const ProcessedRecord& p, Eigen::Index k, int j) {
  const double v = p.record.dq(k, j);
  const bool filtered = p.moving_positive.size() != 0;
  const double pos = filtered ? p.moving_positive(k, j) : static_cast<double>(v > 0.0);
  const double neg = filtered ? p.moving_negative(k, j) : static_cast<double>(v < 0.0);
  return {v > 0.0 ? v : 0.0, v < 0.0 ? v : 0.0, pos, -neg};
}

/// τ = a·sin q + b·cos q written as k·sin(q + q_off) with q_off in (−π/2, π/2] (seed 2 eq. 23),
/// and the standard deviations of k and q_off from the 2×2 covariance C of (a, b) by the delta
/// method: ∂k/∂(a, b) = (a, b)/k, ∂q_off/∂(a, b) = (−b, a)/(a² + b²).
struct Sinusoid {
  double k = 0.0, q_off = 0.0, k_std = 0.0, q_off_std = 0.0;
};
Sinusoid sinusoid_from_linear(double a, double b, const Eigen::Matrix2d& C);

}  // namespace dynid::detail
