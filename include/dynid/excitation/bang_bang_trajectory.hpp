#pragma once

#include <Eigen/Core>

#include "dynid/excitation/move_sequence.hpp"

namespace dynid {

/// Bang-bang acceleration moves for friction identification (seed 2 §3.2.2): between consecutive
/// way-points the acceleration is +a then −a (triangular velocity), so the inertia torque changes
/// sign half-way and its hysteresis can be separated from friction. Joints are synchronised: the
/// move lasts T = max_j 2·sqrt(|D_j|/a_j) (the slowest joint uses exactly a_max) and joint j
/// accelerates at 4|D_j|/T² ≤ a_j. Peak speed of joint j: 2|D_j|/T.
class BangBangTrajectory final : public MoveSequence {
 public:
  /// way_points: n×m (m ≥ 2) [rad or m]; a_max: n, > 0; dwell ≥ 0 [s]. Throws dynid::Error for
  /// bad sizes, non-positive limits, NaN, or two identical consecutive way-points.
  BangBangTrajectory(const Eigen::MatrixXd& way_points, const Eigen::VectorXd& a_max,
                     double dwell = 0.0);
};

}  // namespace dynid
