#pragma once

#include <Eigen/Core>

#include "dynid/excitation/trajectory.hpp"

namespace dynid {

/// A trajectory sampled on a uniform time grid; row k is sample k (the CSV layout of docs/design.md
/// section 4: columns t, q1..qn, dq1..dqn, ddq1..ddqn).
struct TrajectorySamples {
  Eigen::VectorXd t;    ///< m sample times [s], t_k = k / rate
  Eigen::MatrixXd q;    ///< m×n joint positions [rad or m]
  Eigen::MatrixXd dq;   ///< m×n joint velocities
  Eigen::MatrixXd ddq;  ///< m×n joint accelerations
};

/// Samples `trajectory` at `rate` Hz from t = 0: m = floor(duration·rate) + 1 samples when
/// `include_end` (the last one at or before duration()), otherwise the samples in [0, duration())
/// (one period of a periodic trajectory without repeating its first sample).
/// Throws dynid::Error if rate is not finite and positive or the trajectory has zero duration.
TrajectorySamples sample_trajectory(const Trajectory& trajectory, double rate,
                                    bool include_end = true);

}  // namespace dynid
