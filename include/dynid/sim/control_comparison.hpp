#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"
#include "dynid/sim/simulate_reference.hpp"

namespace dynid {

/// Tracking errors of one controller, per joint, over the samples after the first period.
struct TrackingErrors {
  std::string controller;           ///< "pid" or "computed-torque"
  Eigen::VectorXd rms;              ///< sqrt(mean e²), e = qr − q (true position) [rad or m]
  Eigen::VectorXd max;              ///< max |e| [rad or m]
  Eigen::VectorXd max_at_reversal;  ///< max |e| within the reversal window of a sign change of
                                    ///< dqr [rad or m]; 0 for a joint whose dqr never changes sign
  Eigen::VectorXi reversals;        ///< sign changes of dqr per period
};

/// Options of compare_control().
struct ControlComparisonOptions {
  /// Plant, sensors, periods (default 3 here) and gains, shared by both controllers; its
  /// feed_forward and controller_model are set per controller. Gains empty = default_pid_options()
  /// for the plain PID (FeedForward::kNone) on the plant's model, used by both.
  SimulateOptions simulate = [] {
    SimulateOptions s;
    s.loop.periods = 3;
    return s;
  }();
  double reversal_window = 0.05;  ///< half-width [s] of the window around a velocity reversal
};

/// The result of compare_control().
struct ControlComparison {
  std::vector<TrackingErrors> controllers;  ///< PID first, then computed torque
  PidGains gains;                           ///< the gains both controllers used
  long samples = 0;                         ///< samples in the statistics (first period left out)
};

/// Seed 2 §3.6, Fig. 9: runs the same periodic reference (t, q, dq, ddq as simulate_reference())
/// on the same plant `plant_model` twice, under the plain PID and under the computed-torque law
/// (FeedForward::kInverseDynamics) whose model is `controller_model` (e.g. identified_model() of a
/// result), with the same gains, and returns per-joint tracking errors after the first period
/// (start-up). Throws dynid::Error for periods < 2, a window < 0 or non-finite, and as
/// simulate_reference() (e.g. a closed loop that diverges).
ControlComparison compare_control(const Model& plant_model, const Model& controller_model,
                                  const Eigen::Ref<const Eigen::VectorXd>& t,
                                  const Eigen::Ref<const Eigen::MatrixXd>& q,
                                  const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                  const Eigen::Ref<const Eigen::MatrixXd>& ddq,
                                  const ControlComparisonOptions& options = {});

/// Marks, for one period of a reference velocity dqr (N samples, periodic), the samples within
/// `window` samples of a sign change (zero samples between two signs do not hide a reversal; the
/// change across the period's end counts). Returns the mask and sets *count to the changes.
std::vector<bool> reversal_mask(const Eigen::Ref<const Eigen::VectorXd>& dqr, long window,
                                int* count);

}  // namespace dynid
