#pragma once

// `dynid simulate` after its files are read (issue 29 item 3): a reference run in closed loop on
// a simulated robot, as the columns the command line writes. The Python module calls it too.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "dynid/model/model.hpp"
#include "dynid/sim/load_sensor.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "dynid/sim/simulate_reference.hpp"

namespace dynid {

/// What simulate_run() adds to simulate_reference().
struct SimulateRunOptions {
  SimulateOptions simulate;          ///< plant, controller, sensors, periods
  std::optional<MountedLoad> load;   ///< a rigid load behind a wrist force/torque sensor, or none
  std::vector<double> wrench_noise;  ///< Gaussian std on the wrench: {} none, {all} or {F, M}
  bool truth = false;                ///< also the true dq, ddq columns
};

/// A simulated run as `dynid simulate` writes it.
struct SimulatedRun {
  /// t, qr1..qrn, q1..qn, tau1..taun [, dq1..dqn, ddq1..ddqn with truth] [, fx fy fz mx my mz
  /// with a load]: the columns of the run CSV.
  std::vector<std::string> columns;
  Eigen::MatrixXd data;  ///< one row per sample, one column per name [s, rad, N·m, N]
  PidOptions pid;        ///< the controller the run used (write_pid_gains())
};

/// simulate_reference() of the reference (t, q, dq, ddq; empty dq or ddq: central differences on
/// t, as read_reference() derives them) on `model` (carrying options.load when given, whose
/// sensor reads the true motion: load_sensor_wrench() plus add_wrench_noise() seeded with the
/// sensor seed + 1). Throws dynid::Error as simulate_reference(), model_with_load() and
/// add_wrench_noise() do, and dynid::UsageError for more than two wrench noise values.
SimulatedRun simulate_run(const Model& model, const Eigen::VectorXd& t, const Eigen::MatrixXd& q,
                          Eigen::MatrixXd dq, Eigen::MatrixXd ddq,
                          const SimulateRunOptions& options);

}  // namespace dynid
