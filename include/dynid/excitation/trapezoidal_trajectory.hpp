#pragma once

#include <Eigen/Core>

#include "dynid/excitation/move_sequence.hpp"

namespace dynid {

/// Point-to-point moves with trapezoidal velocity, used to validate an identified model (seed 2
/// §3.5: "reference trajectories with trapezoidal velocity shape"). Between consecutive way-points
/// all joints start and stop together: the move lasts T = max_j (D_j/v_j + v_j/a_j) (the slowest
/// joint reaches exactly v_max and a_max), and every other joint keeps its a_max and cruises at
/// the lower speed v = (a·T − sqrt(a²T² − 4·a·D))/2 that ends it at T. |D_j| = v(T − v/a).
class TrapezoidalTrajectory final : public MoveSequence {
 public:
  /// way_points: n×m (column k = way-point k, m ≥ 2) [rad or m]; v_max, a_max: n, > 0; dwell ≥ 0
  /// rest between moves [s]. Throws dynid::Error for bad sizes, non-positive limits, NaN, and
  /// when a joint's move is too short to reach its v_max (|D| < v_max²/a_max: lower v_max to at
  /// most sqrt(|D|·a_max), or use BangBangTrajectory).
  TrapezoidalTrajectory(const Eigen::MatrixXd& way_points, const Eigen::VectorXd& v_max,
                        const Eigen::VectorXd& a_max, double dwell = 0.0);
};

}  // namespace dynid
