#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynid/excitation/trajectory.hpp"

namespace dynid {

/// One synchronised joint-space move from `q_start` to `q_start + distance` in `duration` seconds.
/// Joint j follows a symmetric piecewise-constant acceleration profile: +a_j·s_j for
/// `accel_time[j]`, zero, then −a_j·s_j for the last `accel_time[j]` (s_j = sign of the distance).
/// accel_time = duration/2 is a bang-bang (triangular velocity) profile, smaller values a
/// trapezoidal one with cruise velocity a_j·accel_time[j]. Identity: |distance_j| =
/// a_j·ta_j·(duration − ta_j).
struct Move {
  double start_time = 0.0;       ///< [s]
  double duration = 0.0;         ///< [s], common to all joints (synchronised move)
  Eigen::VectorXd q_start;       ///< n start positions [rad or m]
  Eigen::VectorXd distance;      ///< n signed displacements [rad or m]
  Eigen::VectorXd acceleration;  ///< n acceleration magnitudes a_j ≥ 0 [rad/s² or m/s²]
  Eigen::VectorXd accel_time;    ///< n acceleration-phase lengths ta_j ∈ [0, duration/2] [s]
  /// Cruise (peak) velocity magnitude of joint j, a_j·ta_j.
  double cruise_velocity(int j) const { return acceleration[j] * accel_time[j]; }
};

/// A sequence of rest-to-rest moves through way-points with an optional dwell (rest) between
/// them. Base of the trapezoidal, bang-bang and slope trajectories; evaluate() is O(log moves).
class MoveSequence : public Trajectory {
 public:
  int dof() const override { return static_cast<int>(start_.size()); }
  double duration() const override { return duration_; }
  void evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> dq,
                Eigen::Ref<Eigen::VectorXd> ddq) const override;

  /// The moves in time order.
  const std::vector<Move>& moves() const { return moves_; }

 protected:
  /// Builds the timing: moves_ must be filled with start_time set by this call (moves follow each
  /// other with `dwell` seconds of rest in between).
  void finish(const Eigen::VectorXd& start, double dwell);
  std::vector<Move> moves_;

 private:
  Eigen::VectorXd start_;
  double duration_ = 0.0;
};

}  // namespace dynid
