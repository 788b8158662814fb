#include "dynid/sim/simulate_reference.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/signal/sampling_check.hpp"

namespace dynid {

namespace {

// ω·(loop lag) of the delay-free rule at its tightest (rate ≤ 320 Hz: ω = 2π·rate/40, lag = Ts +
// 2·Ts): 2π·3/40. Keeping ω·lag at or below it keeps the phase lost to the lag at ~27° whatever
// the measurement delay, so the delay-free loops are unchanged and delayed ones stay stable.
constexpr double kLoopLagBudget = 2 * M_PI * 3.0 / 40.0;

}  // namespace

PidOptions default_pid_options(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q0,
                               double rate_hz, int delay_samples, FeedForward feed_forward) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz))
    throw Error("controller rate must be finite and > 0 Hz, got " + short_number(rate_hz));
  if (delay_samples < 0)
    throw Error("measurement delay must be >= 0 samples, got " + std::to_string(delay_samples));
  Workspace ws(model);
  Eigen::MatrixXd M(model.dof(), model.dof());
  mass_matrix(model, ws, q0, M);
  PidOptions o;
  o.sample_time = 1.0 / rate_hz;
  o.derivative_filter_time = std::max(o.derivative_filter_time, 2.0 / rate_hz);
  // A discrete loop needs its bandwidth well below the sample rate (rate/40) and below the
  // inverse of its lag; a derivative filter of at least two samples.
  const double lag = (delay_samples + 1) * o.sample_time + o.derivative_filter_time;
  double w = 2 * M_PI * std::min(8.0, rate_hz / 40.0);
  if (delay_samples > 0) w = std::min(w, kLoopLagBudget / lag);  // inactive without delay
  // Gains per joint ∝ M_jj place the modes of M·ë = −K·e at ω·sqrt(μ), μ the eigenvalues of
  // M⁻¹·diag(M) ≥ 1 on average; coupling (planar2's elbow, a 7-joint arm's light wrist) makes
  // μ_max ≫ 1, a fast mode a delayed or feedback-only loop cannot hold. Dividing by μ_max keeps
  // every mode at or below ω. The delay-free feed-forward loop keeps its historical gains, which
  // recorded runs and validate_run_by_simulation() rely on.
  double mu_max = 1.0;
  if (delay_samples > 0 || feed_forward == FeedForward::kNone) {
    const Eigen::VectorXd d_sqrt = M.diagonal().cwiseSqrt();
    const Eigen::MatrixXd scaled =
        d_sqrt.asDiagonal() * M.ldlt().solve(Eigen::MatrixXd(d_sqrt.asDiagonal()));
    mu_max = std::max(1.0, Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(
                               0.5 * (scaled + scaled.transpose()), Eigen::EigenvaluesOnly)
                               .eigenvalues()
                               .maxCoeff());
  }
  o.kp = M.diagonal() * w * w / mu_max;  // this order: bit-identical historical gains at μ = 1
  o.kd = M.diagonal() * 2 * 0.9 * w / mu_max;
  o.ki = o.kp * 0.5;
  o.feed_forward = feed_forward;
  o.effort_limit = Eigen::VectorXd::Constant(model.dof(), 1e6);
  return o;
}

PidOptions simulation_pid_options(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q0,
                                  double rate_hz, const SimulateOptions& options) {
  PidOptions o =
      default_pid_options(model, q0, rate_hz, options.sensors.position_delay, options.feed_forward);
  if (options.gains.kp.size() > 0) {
    o.kp = options.gains.kp;
    o.ki = options.gains.ki;
    o.kd = options.gains.kd;
  }
  PidController check(model, o);  // the controller's own checks: sizes, finite, >= 0
  return check.options();
}

namespace {

// One period of a uniformly sampled reference; a last sample equal to the first ends the period.
Reference periodic_reference(const Eigen::Ref<const Eigen::VectorXd>& t,
                             const Eigen::Ref<const Eigen::MatrixXd>& q,
                             const Eigen::Ref<const Eigen::MatrixXd>& dq,
                             const Eigen::Ref<const Eigen::MatrixXd>& ddq) {
  Eigen::Index m = t.size();
  if (m > 2 && (q.row(m - 1) - q.row(0)).norm() < 1e-9 * std::max(1.0, q.row(0).norm())) --m;
  return Reference{t.head(m), q.topRows(m), dq.topRows(m), ddq.topRows(m)};
}

// A tracking loop's positions stay near its reference: beyond the reference's robust span (1st to
// 99th percentile, so a corrupt row does not widen it) by more than that span plus half a turn, a
// value is a corrupt reference row or a plant gone unstable.
constexpr double kDivergenceMargin = M_PI;
constexpr double kBandPercentile = 0.01;

struct Band {
  double lo, hi;  // robust span of the reference
  double margin;  // allowed distance outside [lo, hi]
  bool contains(double x) const { return x >= lo - margin && x <= hi + margin; }
};

Band robust_band(const Eigen::Ref<const Eigen::VectorXd>& x) {
  std::vector<double> v(x.data(), x.data() + x.size());
  const auto at = [&](double p) {
    const auto k = static_cast<std::ptrdiff_t>(p * static_cast<double>(v.size() - 1));
    std::nth_element(v.begin(), v.begin() + k, v.end());
    return v[static_cast<std::size_t>(k)];
  };
  const double lo = at(kBandPercentile), hi = at(1.0 - kBandPercentile);
  return {lo, hi, (hi - lo) + kDivergenceMargin};
}

// Throws dynid::Error naming the first reference row far outside the rest of the reference.
void check_reference_rows(const Model& model, const Eigen::Ref<const Eigen::MatrixXd>& q) {
  for (Eigen::Index j = 0; j < q.cols(); ++j) {
    const Band band = robust_band(q.col(j));
    for (Eigen::Index k = 0; k < q.rows(); ++k) {
      if (!band.contains(q(k, j))) {
        throw Error("simulate: reference sample " + std::to_string(k + 1) + ": joint " +
                    model.joints[j].name + " at q = " + short_number(q(k, j)) +
                    " is far outside the rest of the reference [" + short_number(band.lo) + ", " +
                    short_number(band.hi) +
                    "]; fix that row of the reference (a corrupt value or unit)");
      }
    }
  }
}

// Throws dynid::Error when the simulated run is not a tracking of the reference: a non-finite
// logged value (sensor noise that overflows, an unstable plant), or a joint far outside the
// reference's band (a plant driven unstable by the reference's feed-forward or by the model).
void check_simulated_run(const Model& model, const ClosedLoopResult& r, const Reference& ref,
                         const SensorOptions& sensors, const std::string& gains_fix) {
  if (!r.tau.allFinite()) {
    throw Error("simulate: the logged torques are not finite (torque noise std " +
                short_number(sensors.torque_noise_std) +
                " N·m, or an unstable plant); use a torque noise well below the torques" +
                gains_fix);
  }
  if (!r.q.allFinite()) {
    throw Error("simulate: the logged positions are not finite (position noise std " +
                short_number(sensors.position_noise_std) +
                " rad, or an unstable plant); use a realistic noise and check the reference" +
                gains_fix);
  }
  for (Eigen::Index j = 0; j < r.q.cols(); ++j) {
    Band band = robust_band(ref.q.col(j));
    band.margin += 10.0 * sensors.position_noise_std;
    for (Eigen::Index k = 0; k < r.q.rows(); ++k) {
      if (!band.contains(r.q(k, j))) {
        throw Error("simulate: the closed loop diverged: joint " + model.joints[j].name +
                    " reached q = " + short_number(r.q(k, j)) + " at t = " + short_number(r.t[k]) +
                    " s while the reference stays in [" + short_number(band.lo) + ", " +
                    short_number(band.hi) +
                    "]; check the reference's dq and ddq columns (feed-forward) and the model's "
                    "masses and inertias" +
                    gains_fix);
      }
    }
  }
}

}  // namespace

ClosedLoopResult simulate_reference(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& t,
                                    const Eigen::Ref<const Eigen::MatrixXd>& q,
                                    const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
                                    SimulateOptions options, PidOptions* controller_used) {
  const SamplingInfo info = require_uniform_sampling(t, 1e-6, "closed-loop simulation");
  const Reference ref = periodic_reference(t, q, dq, ddq);
  check_reference_rows(model, ref.q);
  // Work and memory grow with periods × samples and with the delay line: bounded here, so that a
  // mistyped count is one error line instead of a run that allocates until the machine stops.
  const double samples = static_cast<double>(options.loop.periods) * ref.t.size();
  if (samples > kMaxSimulatedSamples) {
    throw Error("simulate: " + std::to_string(options.loop.periods) + " periods of " +
                std::to_string(ref.t.size()) + " samples are " + short_number(samples) +
                " samples, more than the " + short_number(kMaxSimulatedSamples) +
                " a simulation may have; lower --periods");
  }
  const int delay = std::max(options.sensors.position_delay, options.sensors.torque_delay);
  if (delay >= ref.t.size()) {
    throw Error("simulate: a measurement delay of " + std::to_string(delay) +
                " samples is not shorter than one period of the reference (" +
                std::to_string(ref.t.size()) + " samples); give a --delay below " +
                std::to_string(ref.t.size()));
  }
  options.plant.dt = info.mean_period;
  const Model& controller_model = options.controller_model ? *options.controller_model : model;
  if (controller_model.dof() != model.dof())
    throw Error("simulate: the controller's model has " + std::to_string(controller_model.dof()) +
                " joints but the robot has " + std::to_string(model.dof()) +
                "; give parameters identified on this robot");
  auto plant = make_plant(model, options.plant);
  PidController pid(controller_model,
                    simulation_pid_options(model, q.row(0).transpose(), info.rate_hz(), options));
  if (controller_used != nullptr) *controller_used = pid.options();
  Sensors sensors(model, options.sensors);
  // An unstable loop shows up as the plant's divergence or a joint leaving the reference's band;
  // the gains are then the likely fault (the default rule does not hold every arm: iiwa14,
  // docs/methods/sim.md), so the error names the flag that replaces them.
  const std::string fix =
      options.gains.kp.size() > 0
          ? "; if the loop is unstable, give other gains with --gains FILE"
          : "; the default gains (docs/methods/sim.md) may not hold this robot: give stable gains "
            "with --gains FILE (kp, ki, kd per joint)";
  ClosedLoopResult result;
  try {
    result = run_closed_loop(ref, pid, *plant, sensors, options.loop);
  } catch (const Error& e) {
    throw Error(std::string("simulate: the closed loop failed: ") + e.what() + fix);
  }
  check_simulated_run(model, result, ref, options.sensors, fix);
  return result;
}

SimulationValidation validate_run_by_simulation(
    const Model& identified, const Eigen::Ref<const Eigen::VectorXd>& t,
    const Eigen::Ref<const Eigen::MatrixXd>& q, const Eigen::Ref<const Eigen::MatrixXd>& dq,
    const Eigen::Ref<const Eigen::MatrixXd>& ddq,
    const Eigen::Ref<const Eigen::MatrixXd>& q_measured,
    const Eigen::Ref<const Eigen::MatrixXd>& tau_measured, const PlantOptions& plant,
    FeedForward feed_forward, const PidGains& gains) {
  const SamplingInfo info = require_uniform_sampling(t, 1e-6, "validation by simulation");
  const Reference ref = periodic_reference(t, q, dq, ddq);
  SimulationValidationOptions options;
  options.plant = plant;
  options.plant.dt = info.mean_period;
  options.skip_samples = std::min<long>(ref.t.size(), q_measured.rows() / 2);
  SimulateOptions controller;
  controller.feed_forward = feed_forward;
  controller.gains = gains;
  return validate_by_simulation(
      identified, ref,
      simulation_pid_options(identified, q.row(0).transpose(), info.rate_hz(), controller),
      q_measured, tau_measured, options);
}

}  // namespace dynid
