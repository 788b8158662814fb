#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Feed-forward torque added to the PID output before saturation.
enum class FeedForward {
  kNone,            ///< pure PID
  kComputedTorque,  ///< tau_ff = rnea(model, qr, dqr, ddqr) with joint terms (seed 2 §3.6)
  /// Computed-torque law (seed 2 §3.6; docs/methods/control.md): the PID output, divided by the
  /// joint inertias D it was tuned for, is an acceleration correction, and the model turns it into
  /// torque at the measured position: tau = rnea(model; y, dqr, ddqr + D⁻¹·u_pid)
  ///   = M(y)·(ddqr + D⁻¹·u_pid) + c(y, dqr) + g(y) + friction(dqr).
  kInverseDynamics,
};

/// Options of the discrete joint PID controller. Gains are per joint; sizes must equal the DoF.
struct PidOptions {
  Eigen::VectorXd kp;                    ///< proportional gains [N·m/rad or N/m]
  Eigen::VectorXd ki;                    ///< integral gains [N·m/(rad·s)]; empty = zeros
  Eigen::VectorXd kd;                    ///< derivative gains [N·m·s/rad]; empty = zeros
  double sample_time = 1e-3;             ///< controller period Ts [s]; > 0
  double derivative_filter_time = 1e-3;  ///< time constant Tf of the first-order filter on the
                                         ///< measured velocity [s]; 0 = plain backward difference
  bool reference_velocity = true;  ///< D term Kd·(dqr − v_f) (true) or −Kd·v_f (false); the
                                   ///< reference is never differentiated (no derivative kick)
  Eigen::VectorXd effort_limit;    ///< |tau| limit per joint [N·m or N]; empty = the model's
                                   ///< Joint::limits.effort (infinite = no saturation)
  bool anti_windup = true;  ///< conditional integration: the integral is frozen while the output
                            ///< is saturated and the error would drive it further out
  FeedForward feed_forward = FeedForward::kNone;  ///< feed-forward torque
  Eigen::VectorXd inertia;  ///< kInverseDynamics only: D, per joint the inertia the gains were
                            ///< tuned for [kg·m² or kg]; empty = diag M(y0) of the controller's
                            ///< model at reset(), so near y0 the loop has the PID's bandwidth
};

/// Discrete PID on every joint, derivative on the measurement through a first-order filter,
/// output saturation at the effort limit, anti-windup, optional computed-torque feed-forward.
/// At sample k, with e_k = qr_k − y_k:
///   v_k = (Tf·v_{k−1} + y_k − y_{k−1}) / (Tf + Ts)     (backward-Euler of s/(1 + Tf·s))
///   I_k = I_{k−1} + Ts·Ki·e_k                         (frozen by anti-windup, see PidOptions)
///   u_k = Kp·e_k + I_k + Kd·(dqr_k − v_k) + tau_ff_k,  tau_k = clamp(u_k, −L, L).
/// Its continuous limit is u = (Kp + Ki/s)·e + Kd·(s·r − s/(1 + Tf·s)·y) + tau_ff. With
/// FeedForward::kInverseDynamics the PID part p_k = Kp·e_k + I_k + Kd·(dqr_k − v_k) instead enters
/// u_k = rnea(model; y_k, dqr_k, ddqr_k + D⁻¹·p_k) (the model is the one given to the
/// constructor, e.g. identified_model(): its base parameters give M and the other terms).
class PidController {
 public:
  /// Checks the options against `model` (copied for the feed-forward and limits). Throws
  /// dynid::Error naming the field at fault (sizes, negative or non-finite gains, Ts ≤ 0, an
  /// inertia that is not finite and > 0).
  PidController(const Model& model, const PidOptions& options);

  /// Clears the integral and the filter; y0 (size n) is the first measurement, so the filtered
  /// velocity starts at 0 without a derivative kick. kInverseDynamics without options.inertia:
  /// D = diag M(y0); throws dynid::Error when an entry is not > 0 (a joint moving no mass).
  void reset(const Eigen::Ref<const Eigen::VectorXd>& y0);

  /// One controller sample: from the reference (qr, dqr, ddqr) and the measured position y (all
  /// size n) computes the saturated torque tau (size n). No allocation.
  void update(const Eigen::Ref<const Eigen::VectorXd>& qr,
              const Eigen::Ref<const Eigen::VectorXd>& dqr,
              const Eigen::Ref<const Eigen::VectorXd>& ddqr,
              const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Ref<Eigen::VectorXd> tau);

  /// The integral state I_k (size n) [N·m].
  const Eigen::VectorXd& integral() const { return integral_; }
  /// D of kInverseDynamics (size n) [kg·m²]; empty before reset() when not given.
  const Eigen::VectorXd& inertia() const { return inertia_; }
  /// The effective saturation limits (size n) [N·m].
  const Eigen::VectorXd& effort_limit() const { return limit_; }
  /// Controller period Ts [s].
  double sample_time() const { return options_.sample_time; }
  /// The options in use (gains resized to n).
  const PidOptions& options() const { return options_; }

 private:
  // Filter step of joint j for measurement y; returns the candidate integral I_k for error e.
  double pid_step(int j, double e, double y);
  // Clamps u to the limit of joint j and keeps `integral` unless anti-windup freezes it.
  double saturate(int j, double u, double e, double integral);
  void update_inverse_dynamics(const Eigen::Ref<const Eigen::VectorXd>& qr,
                               const Eigen::Ref<const Eigen::VectorXd>& dqr,
                               const Eigen::Ref<const Eigen::VectorXd>& ddqr,
                               const Eigen::Ref<const Eigen::VectorXd>& y,
                               Eigen::Ref<Eigen::VectorXd> tau);

  Model model_;
  PidOptions options_;
  Workspace ws_;
  Eigen::VectorXd limit_, integral_, y_prev_, velocity_, feed_forward_;
  Eigen::VectorXd inertia_, integral_next_, pid_, acceleration_;  // kInverseDynamics
  Eigen::MatrixXd mass_;                                          // M(y0) for the default D
};

}  // namespace dynid
