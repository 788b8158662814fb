#pragma once

#include <Eigen/Core>

#include "dynid/common/progress.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "dynid/sim/plant.hpp"
#include "dynid/sim/sensors.hpp"

namespace dynid {

/// One period of a reference trajectory sampled uniformly at the controller period: rows are
/// samples t_0 … t_{N−1} (the end point t_0 + N·Ts is the next period's first sample and is NOT
/// included), columns joints. E.g. one period of a Fourier excitation (seed 2 eqs. 17–19).
struct Reference {
  Eigen::VectorXd t;    ///< N sample times [s], uniformly spaced by Ts
  Eigen::MatrixXd q;    ///< N×n positions qr [rad or m]
  Eigen::MatrixXd dq;   ///< N×n velocities dqr
  Eigen::MatrixXd ddq;  ///< N×n accelerations ddqr
};

/// Options of run_closed_loop().
struct ClosedLoopOptions {
  int periods = 25;           ///< number of reference periods to run (seed 2 §3.4 uses 25)
  long samples = 0;           ///< total samples; 0 = periods × N (overrides periods when > 0)
  bool record_truth = false;  ///< also return the true q, dq, ddq and the noise-free torque
  Eigen::VectorXd q0;         ///< initial joint positions; empty = qr(t_0)
  Eigen::VectorXd dq0;        ///< initial joint velocities; empty = dqr(t_0)
  ProgressCallback progress;  ///< called every 1000 samples (common/progress.hpp); may be empty
};

/// The logged run: one row per controller sample, t_k = t_0 + k·Ts.
struct ClosedLoopResult {
  Eigen::VectorXd t;         ///< sample times [s]
  Eigen::MatrixXd qr;        ///< reference positions (the periodic reference repeated)
  Eigen::MatrixXd q;         ///< measured positions (sensor model applied)
  Eigen::MatrixXd tau;       ///< measured joint torque: the saturated command applied to the
                             ///< joints over [t_k, t_k + Ts) plus torque sensor noise/delay
  Eigen::MatrixXd q_true;    ///< true positions (record_truth only, else empty)
  Eigen::MatrixXd dq_true;   ///< true velocities (record_truth only)
  Eigen::MatrixXd ddq_true;  ///< true accelerations at t_k under tau_k (record_truth only)
  Eigen::MatrixXd tau_true;  ///< applied torque without sensor effects (record_truth only)
};

/// Checks a reference for `dof` joints and sample time `ts`: ≥ 2 samples, matching sizes, finite
/// values, uniform spacing equal to ts (relative 1e-6). Throws dynid::Error naming the fault.
void check_reference(const Reference& reference, int dof, double ts);

/// Runs the loop sensors → PID → plant for options.samples (or periods × N) samples. At sample k:
/// y_k = sensors(q(t_k)); tau_k = pid(qr_k, dqr_k, ddqr_k, y_k); the plant integrates [t_k, t_k+Ts)
/// with tau_k held (zero-order hold); the log gets (t_k, qr_k, y_k, sensors(tau_k)). The plant is
/// reset to (q0, dq0), the controller and the sensors are reset. Requires plant.dt() ==
/// controller.sample_time() == the reference spacing (relative 1e-6); throws dynid::Error naming
/// the mismatch, the reference fault, or a plant divergence.
ClosedLoopResult run_closed_loop(const Reference& reference, PidController& controller,
                                 Plant& plant, Sensors& sensors,
                                 const ClosedLoopOptions& options = {});

}  // namespace dynid
