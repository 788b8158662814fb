#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynid/sim/closed_loop.hpp"
#include "dynid/sim/error_statistics.hpp"

namespace dynid {

/// Options of validate_by_simulation().
struct SimulationValidationOptions {
  PlantOptions plant;     ///< simulator for the identified model (dt = controller Ts)
  long skip_samples = 0;  ///< initial samples left out of the statistics (start-up transient)
  bool start_at_measured = true;  ///< start the simulation at the first measured position
                                  ///< (true) or at the reference (false)
};

/// Result of validate_by_simulation().
struct SimulationValidation {
  ClosedLoopResult simulated;             ///< the simulated run of the identified model
  Eigen::MatrixXd position_error;         ///< q_measured − q_simulated (N×n) [rad or m]
  Eigen::MatrixXd torque_error;           ///< tau_measured − tau_simulated (N×n) [N·m or N]
  std::vector<ErrorStatistics> position;  ///< per joint, over samples skip_samples … N−1
  std::vector<ErrorStatistics> torque;    ///< per joint, over samples skip_samples … N−1
};

/// Validation by simulation (seed 2 §3.5): simulates `identified` (a Model carrying identified
/// parameters) in closed loop under the same periodic `reference` and controller options as a
/// measured run, with noise-free sensors, for as many samples as the measured run, and reports
/// per joint the statistics of the position and torque errors measured − simulated.
/// q_measured, tau_measured: N×n, sampled at the controller period from the reference's t_0.
/// Throws dynid::Error for size mismatches, non-finite data, skip_samples leaving < 2 samples,
/// and every error of run_closed_loop().
SimulationValidation validate_by_simulation(const Model& identified, const Reference& reference,
                                            const PidOptions& controller,
                                            const Eigen::Ref<const Eigen::MatrixXd>& q_measured,
                                            const Eigen::Ref<const Eigen::MatrixXd>& tau_measured,
                                            const SimulationValidationOptions& options = {});

}  // namespace dynid
