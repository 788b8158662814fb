#pragma once

#include <Eigen/Core>

#include "dynid/sim/closed_loop.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "dynid/sim/plant.hpp"
#include "dynid/sim/sensors.hpp"
#include "dynid/sim/simulation_validation.hpp"

namespace dynid {

/// PID gains that give every joint the same closed-loop bandwidth for its own inertia (diagonal
/// of M(q0), actuator inertia included): kp = M_jj·ω², kd = 2ζ·M_jj·ω, ki = kp/2, ω = 2π·min(8 Hz,
/// rate/40), ζ = 0.9, derivative filter ≥ 2 samples, with computed-torque feed-forward (seed 2
/// §3.6) and sample time 1/rate.
PidOptions default_pid_options(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q0,
                               double rate_hz);

/// Options of simulate_reference().
struct SimulateOptions {
  PlantOptions plant;      ///< engine (native or MuJoCo); dt is set from the reference
  SensorOptions sensors;   ///< quantisation, noise, delays
  ClosedLoopOptions loop;  ///< periods (25), truth recording
};

/// Runs one periodic reference (t uniform, one period; a last sample equal to the first is the
/// period's end and is dropped) in closed loop on the plant with default_pid_options() and
/// returns the logged run (t, qr, q, tau, and the truth when asked). t: m, q/dq/ddq: m × n.
/// Throws dynid::Error for a non-uniform or too short reference, or sizes that do not match, for a
/// reference row far outside the rest of the reference, and when the run is not a tracking of the
/// reference: a non-finite logged value (noise that overflows, a plant gone unstable) or a joint
/// leaving [P1 − span − π, P99 + span + π], P1/P99 the reference's percentiles, span = P99 − P1.
ClosedLoopResult simulate_reference(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& t,
                                    const Eigen::Ref<const Eigen::MatrixXd>& q,
                                    const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
                                    SimulateOptions options);

/// Validation by simulation (seed 2 §3.5) of a measured run made with simulate_reference()'s
/// controller: simulates `identified` under the same reference (one period, as for
/// simulate_reference) and default_pid_options(), and compares with q_measured, tau_measured
/// (N×n from t_0 of the reference at its rate). The first period is left out of the statistics.
SimulationValidation validate_run_by_simulation(
    const Model& identified, const Eigen::Ref<const Eigen::VectorXd>& t,
    const Eigen::Ref<const Eigen::MatrixXd>& q, const Eigen::Ref<const Eigen::MatrixXd>& dq,
    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
    const Eigen::Ref<const Eigen::MatrixXd>& q_measured,
    const Eigen::Ref<const Eigen::MatrixXd>& tau_measured, const PlantOptions& plant);

}  // namespace dynid
