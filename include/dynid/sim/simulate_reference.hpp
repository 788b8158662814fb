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

/// PID gains that hold the arm along a reference (docs/methods/sim.md, "default gain rule"): at
/// up to 64 configurations q_k evenly spaced along q_reference (samples × n [rad or m]), D_j =
/// min_k 1/(M(q_k)⁻¹)_jj (the "free" inertia, actuator inertia included) and μ = max(1, max_k
/// λ_max(D^½·M(q_k)⁻¹·D^½)); kp = D·ω²/μ, so every mode of M(q)·ë = −K·e stays at or below ω in
/// every configuration met; kd = kp·2ζ/ω (ζ = 0.9), ki = kp/2, derivative filter Tf ≥ 2 samples,
/// sample time Ts = 1/rate, and
///   ω = min(2π·8 Hz, 2π·rate/40, kLoopLagBudget / ((delay + 1)·Ts + Tf)),
/// the lag bound active only with a delay. Without feed-forward (plain PID) each kp_j is raised to
/// max_k|g_j(q_k)|/0.02 rad, at most D_j·ω² (a stiffness floor: a light joint holds its gravity
/// torque). feed_forward: computed torque (seed 2 §3.6) or none (plain PID). Throws dynid::Error
/// for rate_hz ≤ 0, delay_samples < 0, a reference of the wrong width or not finite, or a model
/// giving a joint no inertia.
PidOptions reference_pid_options(const Model& model,
                                 const Eigen::Ref<const Eigen::MatrixXd>& q_reference,
                                 double rate_hz, int delay_samples = 0,
                                 FeedForward feed_forward = FeedForward::kComputedTorque);

/// The earlier single-configuration rule, kept for the demo and the tests whose measured
/// numbers rely on it (simulate uses reference_pid_options()): kp = M_jj(q0)·ω²/μ, kd =
/// 2ζ·M_jj(q0)·ω/μ, ki = kp/2, ω as in reference_pid_options(), μ = λ_max(M⁻¹·diag M) at q0 for
/// a plain PID or a delay and 1 for the delay-free feed-forward loop (whose coupled mode can then
/// be unstable: planar2 stretched, iiwa14; docs/methods/sim.md). Throws dynid::Error for
/// rate_hz ≤ 0 or delay_samples < 0.
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
  PidGains gains;  ///< user gains; empty kp = reference_pid_options() for the position delay
  /// The model inside the controller (feed-forward, computed-torque law), e.g. identified_model()
  /// of a result; empty = the plant's model. Same joints as the plant's model.
  std::optional<Model> controller_model;
};

/// The controller simulate_reference() runs for a reference q_reference (samples × n) sampled at
/// rate_hz: options.gains when given (the rest of the default options kept), else
/// reference_pid_options() with options.sensors.position_delay; options.feed_forward in both
/// cases. Throws dynid::Error for gains of the wrong size, negative or non-finite.
PidOptions simulation_pid_options(const Model& model,
                                  const Eigen::Ref<const Eigen::MatrixXd>& q_reference,
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
