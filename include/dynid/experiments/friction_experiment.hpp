#pragma once

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"
#include "dynid/experiments/gravity_experiment.hpp"
#include "dynid/identification/known_friction.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Options of fit_friction_experiment() (Ceres style).
struct FrictionExperimentOptions {
  /// Two-sided level of the intervals, in (0, 1); 0.999 as seed 2 Table 3.
  double confidence_level = 0.999;
  /// Samples with |dq_J| below max(zero_velocity_fraction·max|dq_J|, zero_velocity_noise_multiple
  /// ·σ_dq) are left out: below a few percent of the peak speed real friction leaves the
  /// Coulomb-plus-viscous law (pre-sliding, Stribeck), and a dedicated friction run has samples at
  /// every speed, so dropping that band costs little. Larger than identify()'s 1 % for that reason.
  double zero_velocity_fraction = 0.05;
  /// See zero_velocity_fraction; σ_dq is the prepared run's velocity noise std.
  double zero_velocity_noise_multiple = 3.0;
  /// Points of the fitted friction curve written for plotting, from −max|dq_J| to +max|dq_J|.
  int curve_points = 101;
  /// The gravity torque of joint J identified by a gravity or decoupled experiment (seed 2 §3.2):
  /// replaces the model's g(q)_J in the compensation. Unset: the model's gravity.
  std::optional<JointGravityModel> gravity;
  /// The equivalent inertia M_J of a decoupled result [kg·m² or kg]: replaces
  /// [M(q)q̈ + c(q, q̇)]_J by M_J·q̈_J (exact for joint J moving alone, seed 2 eqs. 21–22). NaN:
  /// the model's.
  double equivalent_inertia = std::numeric_limits<double>::quiet_NaN();
};

/// Asymmetric viscous and Coulomb friction of one joint (seed 2 §3.2.2, eq. 2, Table 2).
struct FrictionExperimentResult {
  int joint = 0;  ///< 0-based joint index J
  /// Names Fvp<J> Fvn<J> Fcp<J> Fcn<J> (docs/design.md §3) and the estimate of
  /// τ_f = Fvp·dq·[dq>0] + Fvn·dq·[dq<0] + Fcp·[dq>0] − Fcn·[dq<0] with HAC intervals.
  std::vector<std::string> names;
  Estimate estimate;
  Eigen::Index rows = 0;                 ///< samples fitted
  Eigen::Index rows_left_out = 0;        ///< near-still samples left out
  double zero_velocity_threshold = 0.0;  ///< [rad/s or m/s]
  double relative_error = 0.0;           ///< ‖e‖/‖τ_f‖ on the samples fitted
  double residual_rms = 0.0;             ///< [N·m or N]
  /// The fitted curve: velocity grid [rad/s or m/s] and friction torque on it [N·m or N].
  Eigen::VectorXd curve_velocity, curve_torque;
  /// Per fitted sample, for plots: run index, time, velocity, compensated torque τ_f, fit.
  Eigen::VectorXi sample_run;
  Eigen::VectorXd sample_t, sample_dq, sample_tau, sample_fitted;
  std::vector<std::pair<std::string, std::string>> choices;  ///< what was decided and why
  std::vector<std::string> warnings;                         ///< named, human-readable
};

/// Fits asymmetric viscous and Coulomb friction of joint J (seed 2 eq. 2) on runs in which joint
/// J moves (bang-bang or slope, seed 2 §3.2.2), after compensating inertia, Coriolis, centripetal
/// and gravity torques with `model` (its rigid-body and armature parameters: nominal, or identified
/// by identified_model()): τ_f = τ_J − [M(q)q̈ + c(q, q̇) + g(q)]_J, the model's own friction
/// left out. With prepared runs that carry filtered expected-sign columns (preprocess() with the
/// automatic zero-velocity rule), the Coulomb columns are those, so that the filtered torque's
/// smeared step at a reversal is matched (Gautier's parallel filtering). Intervals: HAC over
/// samples. Throws dynid::Error for a joint outside the model, runs of another robot, or data
/// that move J in only one direction (names the direction missing).
FrictionExperimentResult fit_friction_experiment(const Model& model,
                                                 const std::vector<ProcessedRecord>& runs,
                                                 int joint,
                                                 const FrictionExperimentOptions& options = {});

}  // namespace dynid
