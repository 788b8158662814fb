#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynid/excitation/trajectory.hpp"

namespace dynid {

/// Order of the piecewise polynomial.
enum class SplineOrder {
  kCubic,   ///< 3rd order, C2: clamped cubic spline (position, velocity, acceleration continuous)
  kQuintic  ///< 5th order (seed 1 §V test trajectories), C2 quintic Hermite segments
};

/// Options of a via-point spline.
struct SplineOptions {
  SplineOrder order = SplineOrder::kQuintic;  ///< polynomial order of every segment
  /// Optional n×m velocities at the via-points (quintic only); empty = those of the clamped
  /// cubic spline through the same points (zero at both ends).
  Eigen::MatrixXd velocities;
  /// Optional n×m accelerations at the via-points (quintic only); empty = those of the clamped
  /// cubic spline at interior points and zero at both ends (so the motion starts and ends at rest).
  Eigen::MatrixXd accelerations;
};

/// Piecewise polynomial through via-points (t_k, q_k), k = 0..m−1, starting and ending with zero
/// velocity. Cubic: the clamped cubic spline, knot accelerations M_k from the tridiagonal system
/// h_{k−1} M_{k−1} + 2(h_{k−1}+h_k) M_k + h_k M_{k+1} = 6(Δ_k − Δ_{k−1}), with the clamped end
/// rows 2h_0 M_0 + h_0 M_1 = 6Δ_0 and h_{m−2}M_{m−2} + 2h_{m−2}M_{m−1} = −6Δ_{m−2}
/// (Δ_k = (q_{k+1} − q_k)/h_k, h_k = t_{k+1} − t_k). Quintic: on each segment the unique quintic
/// matching position, velocity and acceleration at both ends (quintic Hermite), hence C2.
class PolynomialSpline final : public Trajectory {
 public:
  /// times: m ≥ 2 strictly increasing, times[0] = 0 [s]; points: n×m via-points [rad or m].
  /// Throws dynid::Error for sizes, NaN, non-increasing or non-zero-start times, or velocity /
  /// acceleration matrices of the wrong size (or given for a cubic spline).
  PolynomialSpline(const Eigen::VectorXd& times, const Eigen::MatrixXd& points,
                   const SplineOptions& options = {});

  int dof() const override { return static_cast<int>(points_.rows()); }
  double duration() const override { return times_[times_.size() - 1]; }
  void evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> dq,
                Eigen::Ref<Eigen::VectorXd> ddq) const override;

  SplineOrder order() const { return order_; }
  const Eigen::VectorXd& times() const { return times_; }

 private:
  SplineOrder order_;
  Eigen::VectorXd times_;
  Eigen::MatrixXd points_;
  /// coefficients_[s]: n×6, row j = c0..c5 of joint j on segment s in τ = t − t_s (cubic: c4 =
  /// c5 = 0).
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, 6>> coefficients_;
};

}  // namespace dynid
