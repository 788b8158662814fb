#include "dynid/sim/pid_controller.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"

namespace dynid {

namespace {

// Resizes an optional per-joint vector (empty = zeros) and checks it is finite and >= 0.
Eigen::VectorXd per_joint(const Eigen::VectorXd& v, int n, const char* field, bool required) {
  if (v.size() == 0 && !required) return Eigen::VectorXd::Zero(n);
  if (v.size() != n)
    throw Error(std::string("PID ") + field + " has " + std::to_string(v.size()) +
                " entries but the model has " + std::to_string(n) +
                " joints: give one value per joint");
  for (int j = 0; j < n; ++j)
    if (!(v[j] >= 0.0) || std::isnan(v[j]))
      throw Error(std::string("PID ") + field + " entry " + std::to_string(j + 1) +
                  " must be >= 0 (got " + std::to_string(v[j]) + ")");
  return v;
}

}  // namespace

PidController::PidController(const Model& model, const PidOptions& options)
    : model_(model), options_(options), ws_(model_) {
  const int n = model_.dof();
  options_.kp = per_joint(options.kp, n, "kp", true);
  options_.ki = per_joint(options.ki, n, "ki", false);
  options_.kd = per_joint(options.kd, n, "kd", false);
  for (int j = 0; j < n; ++j)
    if (!std::isfinite(options_.kp[j]) || !std::isfinite(options_.ki[j]) ||
        !std::isfinite(options_.kd[j]))
      throw Error("PID gains of joint " + std::to_string(j + 1) + " must be finite");
  if (!(options_.sample_time > 0.0) || !std::isfinite(options_.sample_time))
    throw Error("PID sample_time must be a finite value > 0 [s], e.g. 0.001");
  if (!(options_.derivative_filter_time >= 0.0) || !std::isfinite(options_.derivative_filter_time))
    throw Error("PID derivative_filter_time must be finite and >= 0 [s] (0 = no filter)");
  if (options.effort_limit.size() == 0) {
    limit_.resize(n);
    for (int j = 0; j < n; ++j) limit_[j] = model_.joints[j].limits.effort;
  } else {
    if (options.effort_limit.size() != n)
      throw Error("PID effort_limit has " + std::to_string(options.effort_limit.size()) +
                  " entries but the model has " + std::to_string(n) +
                  " joints: give one limit per joint or none (model limits)");
    limit_ = options.effort_limit;
  }
  for (int j = 0; j < n; ++j)
    if (!(limit_[j] > 0.0))
      throw Error("PID effort limit of joint '" + model_.joints[j].name +
                  "' must be > 0 [N·m] (use infinity for no saturation)");
  integral_ = Eigen::VectorXd::Zero(n);
  y_prev_ = Eigen::VectorXd::Zero(n);
  velocity_ = Eigen::VectorXd::Zero(n);
  feed_forward_ = Eigen::VectorXd::Zero(n);
  if (options_.feed_forward == FeedForward::kInverseDynamics) {
    if (options.inertia.size() != 0) {
      if (options.inertia.size() != n)
        throw Error("PID inertia has " + std::to_string(options.inertia.size()) +
                    " entries but the model has " + std::to_string(n) +
                    " joints: give one per joint or none (diag M at the first measurement)");
      for (int j = 0; j < n; ++j)
        if (!(options.inertia[j] > 0.0) || !std::isfinite(options.inertia[j]))
          throw Error("PID inertia of joint '" + model_.joints[j].name +
                      "' must be finite and > 0 [kg·m²]");
      inertia_ = options.inertia;
    }
    integral_next_ = Eigen::VectorXd::Zero(n);
    pid_ = Eigen::VectorXd::Zero(n);
    acceleration_ = Eigen::VectorXd::Zero(n);
    mass_ = Eigen::MatrixXd::Zero(n, n);
  }
}

void PidController::reset(const Eigen::Ref<const Eigen::VectorXd>& y0) {
  if (y0.size() != model_.dof())
    throw Error("PID reset: the first measurement must have " + std::to_string(model_.dof()) +
                " entries, got " + std::to_string(y0.size()));
  integral_.setZero();
  velocity_.setZero();
  y_prev_ = y0;
  if (options_.feed_forward == FeedForward::kInverseDynamics && options_.inertia.size() == 0) {
    mass_matrix(model_, ws_, y0, mass_);
    inertia_ = mass_.diagonal();
    for (int j = 0; j < model_.dof(); ++j)
      if (!(inertia_[j] > 0.0) || !std::isfinite(inertia_[j]))
        throw Error("computed-torque control: the model's inertia about joint '" +
                    model_.joints[j].name + "' is " + std::to_string(inertia_[j]) +
                    " at the first position; the model (e.g. identified parameters) must give "
                    "every joint a positive inertia");
  }
}

void PidController::update(const Eigen::Ref<const Eigen::VectorXd>& qr,
                           const Eigen::Ref<const Eigen::VectorXd>& dqr,
                           const Eigen::Ref<const Eigen::VectorXd>& ddqr,
                           const Eigen::Ref<const Eigen::VectorXd>& y,
                           Eigen::Ref<Eigen::VectorXd> tau) {
  const int n = model_.dof();
  if (options_.feed_forward == FeedForward::kInverseDynamics) {
    update_inverse_dynamics(qr, dqr, ddqr, y, tau);
    return;
  }
  if (options_.feed_forward == FeedForward::kComputedTorque)
    rnea(model_, ws_, qr, dqr, ddqr, feed_forward_);
  for (int j = 0; j < n; ++j) {
    const double e = qr[j] - y[j];
    const double integral = pid_step(j, e, y[j]);
    const double u =
        options_.kp[j] * e + integral +
        options_.kd[j] * ((options_.reference_velocity ? dqr[j] : 0.0) - velocity_[j]) +
        feed_forward_[j];
    tau[j] = saturate(j, u, e, integral);
  }
}

double PidController::pid_step(int j, double e, double y) {
  const double ts = options_.sample_time, tf = options_.derivative_filter_time;
  // Filtered derivative of the measurement: backward Euler of s / (1 + Tf·s).
  velocity_[j] = (tf * velocity_[j] + (y - y_prev_[j])) / (tf + ts);
  y_prev_[j] = y;
  return integral_[j] + ts * options_.ki[j] * e;
}

double PidController::saturate(int j, double u, double e, double integral) {
  const double u_sat = std::clamp(u, -limit_[j], limit_[j]);
  // Conditional integration: keep the old integral when saturated and e pushes further out.
  const bool winding = u != u_sat && ((u > 0.0) == (e > 0.0)) && e != 0.0;
  if (!(options_.anti_windup && winding)) integral_[j] = integral;
  return u_sat;
}

void PidController::update_inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& qr,
                                            const Eigen::Ref<const Eigen::VectorXd>& dqr,
                                            const Eigen::Ref<const Eigen::VectorXd>& ddqr,
                                            const Eigen::Ref<const Eigen::VectorXd>& y,
                                            Eigen::Ref<Eigen::VectorXd> tau) {
  const int n = model_.dof();
  if (inertia_.size() != n) throw Error("computed-torque control: call reset() before update()");
  for (int j = 0; j < n; ++j) {
    const double e = qr[j] - y[j];
    integral_next_[j] = pid_step(j, e, y[j]);
    pid_[j] = options_.kp[j] * e + integral_next_[j] +
              options_.kd[j] * ((options_.reference_velocity ? dqr[j] : 0.0) - velocity_[j]);
    acceleration_[j] = ddqr[j] + pid_[j] / inertia_[j];
  }
  // The reference velocity in c and the friction: the measured one would bring its noise and,
  // through sign(dq), torque chatter at every reversal (docs/methods/control.md).
  rnea(model_, ws_, y, dqr, acceleration_, feed_forward_);
  for (int j = 0; j < n; ++j)
    tau[j] = saturate(j, feed_forward_[j], qr[j] - y[j], integral_next_[j]);
}

}  // namespace dynid
