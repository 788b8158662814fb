#pragma once

#include <string>

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

/// Most samples a written trajectory may have: 1e7 (28 h at 100 Hz, 2.8 h at 1 kHz; 1.8 GB of
/// doubles for a 7-joint arm). A longer one is a mistyped rate or frequency, not an experiment,
/// and would otherwise allocate until the machine stops.
constexpr double kMaxTrajectorySamples = 1e7;

/// Throws dynid::Error when `duration` [s] at `rate` [Hz] is more than kMaxTrajectorySamples
/// samples, giving both and the fix; `what` names the duration's origin in the message (e.g.
/// "--f0 1e-300 Hz gives a period of"). No throw for a duration or rate that is not positive.
void check_trajectory_samples(double duration, double rate, const std::string& what);

/// Samples `trajectory` at `rate` Hz from t = 0: m = floor(duration·rate) + 1 samples when
/// `include_end` (the last one at or before duration()), otherwise the samples in [0, duration())
/// (one period of a periodic trajectory without repeating its first sample).
/// Throws dynid::Error if rate is not finite and positive, the trajectory has zero duration, or it
/// needs more than kMaxTrajectorySamples samples (check_trajectory_samples).
TrajectorySamples sample_trajectory(const Trajectory& trajectory, double rate,
                                    bool include_end = true);

}  // namespace dynid
