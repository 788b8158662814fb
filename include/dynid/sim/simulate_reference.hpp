#pragma once

#include <optional>
#include <string>

#include <Eigen/Core>

#include "dynid/sim/closed_loop.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "dynid/sim/plant.hpp"
#include "dynid/sim/sensors.hpp"
#include "dynid/sim/simulation_validation.hpp"

namespace dynid {

/// PID gains that give every joint the same closed-loop bandwidth for its own inertia (diagonal
/// of M(q0), actuator inertia included): kp = M_jj·ω², kd = 2ζ·M_jj·ω, ki = kp/2, ζ = 0.9,
/// derivative filter Tf ≥ 2 samples, sample time Ts = 1/rate, and
///   ω = min(2π·8 Hz, 2π·rate/40, kLoopLagBudget / ((delay + 1)·Ts + Tf)),
/// i.e. the bandwidth also shrinks with the loop's lag (measurement delay, zero-order hold plus
/// computation, derivative filter) so that the phase margin stays the same with a measurement
/// delay (docs/methods/sim.md). With delay_samples = 0 the lag bound is inactive and the gains are
/// those of earlier releases. feed_forward: computed torque (seed 2 §3.6) or none (plain PID).
/// Throws dynid::Error for rate_hz ≤ 0 or delay_samples < 0.
PidOptions default_pid_options(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q0,
                               double rate_hz, int delay_samples = 0,
                               FeedForward feed_forward = FeedForward::kComputedTorque);

/// Per-joint PID gains given by the user (e.g. read_pid_gains()); empty kp = the default rule.
struct PidGains {
  Eigen::VectorXd kp;      ///< proportional gains [N·m/rad or N/m], size n
  Eigen::VectorXd ki;      ///< integral gains [N·m/(rad·s)], size n
  Eigen::VectorXd kd;      ///< derivative gains [N·m·s/rad], size n
  std::string controller;  ///< the controller a written gains file names ("pid", ...); may be empty
};

/// Options of simulate_reference().
/// Most samples simulate_reference() runs (periods × samples of the period): 1e7, 28 h at 100 Hz.
inline constexpr double kMaxSimulatedSamples = 1e7;

struct SimulateOptions {
  PlantOptions plant;      ///< engine (native or MuJoCo); dt is set from the reference
  SensorOptions sensors;   ///< quantisation, noise, delays
  ClosedLoopOptions loop;  ///< periods (25), truth recording
  FeedForward feed_forward = FeedForward::kComputedTorque;  ///< kNone = plain PID (seed 2 §2.2)
  PidGains gains;  ///< user gains; empty kp = default_pid_options() for the position delay
  /// The model inside the controller (feed-forward, computed-torque law), e.g. identified_model()
  /// of a result; empty = the plant's model. Same joints as the plant's model.
  std::optional<Model> controller_model;
};

/// The controller simulate_reference() runs for a reference starting at q0 sampled at rate_hz:
/// options.gains when given (the rest of the default options kept), else default_pid_options()
/// with options.sensors.position_delay; options.feed_forward in both cases. Throws dynid::Error
/// for gains of the wrong size, negative or non-finite.
PidOptions simulation_pid_options(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q0,
                                  double rate_hz, const SimulateOptions& options);

/// Runs one periodic reference (t uniform, one period; a last sample equal to the first is the
/// period's end and is dropped) in closed loop on the plant with simulation_pid_options() and
/// returns the logged run (t, qr, q, tau, and the truth when asked). t: m, q/dq/ddq: m × n.
/// Throws dynid::Error for a non-uniform or too short reference, or sizes that do not match, for a
/// reference row far outside the rest of the reference, and when the run is not a tracking of the
/// reference: a non-finite logged value (noise that overflows, a plant gone unstable) or a joint
/// leaving [P1 − span − π, P99 + span + π], P1/P99 the reference's percentiles, span = P99 − P1.
/// When controller_used is not null it receives the controller options the run used. Throws
/// dynid::Error when options.controller_model has another joint count than `model`, when periods ×
/// samples exceed kMaxSimulatedSamples, or a sensor delay is not shorter than one period.
ClosedLoopResult simulate_reference(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& t,
                                    const Eigen::Ref<const Eigen::MatrixXd>& q,
                                    const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
                                    SimulateOptions options, PidOptions* controller_used = nullptr);

/// Validation by simulation (seed 2 §3.5) of a measured run made with simulate_reference()'s
/// controller: simulates `identified` under the same reference (one period, as for
/// simulate_reference) and the controller of simulation_pid_options() with `feed_forward` and
/// `gains` (the run's own loop; kInverseDynamics uses `identified` as the controller's model), and
/// compares with q_measured, tau_measured (N×n from t_0 of the reference at its rate). The first
/// period is left out of the statistics.
SimulationValidation validate_run_by_simulation(
    const Model& identified, const Eigen::Ref<const Eigen::VectorXd>& t,
    const Eigen::Ref<const Eigen::MatrixXd>& q, const Eigen::Ref<const Eigen::MatrixXd>& dq,
    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
    const Eigen::Ref<const Eigen::MatrixXd>& q_measured,
    const Eigen::Ref<const Eigen::MatrixXd>& tau_measured, const PlantOptions& plant,
    FeedForward feed_forward = FeedForward::kComputedTorque, const PidGains& gains = {});

}  // namespace dynid
