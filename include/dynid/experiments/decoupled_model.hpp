#pragma once

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"
#include "dynid/identification/record.hpp"

namespace dynid {

/// Options of fit_decoupled_joint() (Ceres style).
struct DecoupledModelOptions {
  /// Two-sided level of the intervals, in (0, 1); 0.999 as seed 2 Table 3.
  double confidence_level = 0.999;
  /// Samples with |q̇_J| below max(zero_velocity_fraction·max|q̇_J|, zero_velocity_noise_multiple
  /// ·σ_q̇) are left out (Coulomb friction is not a function of q̇ there), as identify() does.
  double zero_velocity_fraction = 0.01;
  double zero_velocity_noise_multiple = 3.0;  ///< see zero_velocity_fraction
  /// A held joint whose position spans more than max(this [rad or m], 10 σ_q) moved: warning.
  double held_motion = 1e-3;
  /// A held joint whose torque varies by more than this fraction of the moving joint's torque
  /// variation (RMS about the mean) is dynamically coupled to it: warning.
  double coupling_warning = 0.2;
};

/// Joint-decoupled model of one joint (seed 2 §3.1, eqs. 21–22).
struct DecoupledJointResult {
  int joint = 0;  ///< 0-based joint index J
  /// τ_J = M·q̈_J + a·sin q_J + b·cos q_J + Fvp·q̇·[q̇>0] + Fvn·q̇·[q̇<0] + Fcp·[q̇>0] − Fcn·[q̇<0]:
  /// names M<J>, a<J>, b<J>, Fvp<J>, Fvn<J>, Fcp<J>, Fcn<J> and their estimate (HAC intervals).
  std::vector<std::string> names;
  Estimate estimate;
  /// Gravity as k·sin(q_J + q_off) (seed 2 eq. 23) with delta-method standard deviations.
  double k = 0.0, q_off = 0.0, k_std = 0.0, q_off_std = 0.0;
  Eigen::Index rows = 0;        ///< samples fitted
  double relative_error = 0.0;  ///< ‖e‖/‖τ_J‖ on the samples fitted
  /// Per joint: the span of its position over the runs [rad or m] and, for the held joints, the
  /// RMS of its torque variation relative to joint J's (0 for J itself): where these are large
  /// the decoupling assumption fails.
  Eigen::VectorXd held_span, coupling_ratio;
  std::vector<std::pair<std::string, std::string>> choices;  ///< what was decided and why
  std::vector<std::string> warnings;                         ///< named, human-readable
};

/// Fits the joint-decoupled model of joint J, M_J·q̈_J + g_J(q_J) + f_J(q̇_J) = τ_J (seed 2 eqs.
/// 21–22; gravity as eq. 23, friction as eq. 2), on prepared runs in which only joint J moves and
/// the others are held. M_J is the equivalent inertia at the held pose (actuator included). For a
/// serial chain with the other joints still this model is exact (M_JJ does not depend on q_J,
/// and the Coriolis and centripetal terms of a single moving joint vanish); the result says
/// where that premise fails: held joints that moved, and held joints carrying large coupling
/// torques (the model will mispredict motions of several joints). Throws dynid::Error for a
/// joint outside the runs, no motion of J, or a rank-deficient fit (names what is missing).
DecoupledJointResult fit_decoupled_joint(const std::vector<ProcessedRecord>& runs, int joint,
                                         const DecoupledModelOptions& options = {});

}  // namespace dynid
