#pragma once

#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/excitation/move_sequence.hpp"

namespace dynid {

/// Constant-velocity slopes in both directions for gravity identification (seed 2 §3.2.1): the
/// joints go q_from → q_to → q_from (`cycles` times) with trapezoidal velocity whose cruise
/// speed is `velocity` (same magnitude, opposite sign on the way back), so that inertia effects
/// vanish on the cruise part and velocity-dependent effects are constant and cancel between the
/// two directions. Synchronised like TrapezoidalTrajectory.
class SlopeTrajectory final : public MoveSequence {
 public:
  /// q_from, q_to: n [rad or m]; velocity, acceleration: n, > 0; cycles ≥ 1; dwell ≥ 0 [s].
  /// Throws dynid::Error for bad sizes/values and when the slope is too short to reach the
  /// velocity (|q_to − q_from| < v²/a: lower the velocity or widen the range).
  SlopeTrajectory(const Eigen::VectorXd& q_from, const Eigen::VectorXd& q_to,
                  const Eigen::VectorXd& velocity, const Eigen::VectorXd& acceleration,
                  int cycles = 1, double dwell = 0.0);

  /// Time intervals [t_begin, t_end] in which every moving joint is at its constant cruise
  /// velocity (one per slope, alternating direction); use these samples for the gravity fit.
  std::vector<std::pair<double, double>> constant_velocity_intervals() const;
};

}  // namespace dynid
