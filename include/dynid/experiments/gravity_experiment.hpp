#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Options of fit_gravity_experiment() (Ceres style).
struct GravityExperimentOptions {
  /// Two-sided level of the intervals, in (0, 1); 0.999 as seed 2 Table 3.
  double confidence_level = 0.999;
  /// A sample lies on a slope's cruise when |dq_J − v| ≤ cruise_tolerance·|v|, v the slope's
  /// cruise velocity (the centre of the most populated velocity band of that relative width in
  /// that direction): there q̈ ≈ 0 and the velocity-dependent torque is constant.
  double cruise_tolerance = 0.05;
  /// A direction is a constant-velocity slope only if its cruise samples are at least this
  /// fraction of its moving samples (|dq_J| above 10 % of the cruise speed); else Error.
  double min_cruise_fraction = 0.3;
  /// Fewest cruise samples for a slope to be used [samples].
  int min_cruise_samples = 10;
  /// fit_gravity_poses(): a gravity base parameter counts as determined by the poses of the runs
  /// only if its column, at each run's mean pose, is independent of the columns before it by at
  /// least this relative residual; poses closer than about this [rad] count as one pose.
  double distinct_pose_tolerance = 1e-3;
};

/// Gravity of one joint from constant-velocity slopes (seed 2 §3.2.1, Table 1).
struct GravityExperimentResult {
  int joint = 0;  ///< 0-based joint index J
  /// τ_g = k·sin(q_J + q_off) (seed 2 eq. 23), q_off in (−π/2, π/2] [N·m or N], [rad].
  double k = 0.0, q_off = 0.0;
  double k_std = 0.0, q_off_std = 0.0;  ///< HAC standard deviations (delta method)
  /// Interval half-widths at confidence_level (the fixed-b critical value of the HAC intervals).
  double k_ci_half_width = 0.0, q_off_ci_half_width = 0.0;
  double confidence_level = 0.0;
  /// Per slope (run, direction): name ("run 1 +"), cruise velocity [rad/s or m/s], constant
  /// torque c of its Coriolis, centripetal and friction terms [N·m or N], its std, and rows.
  std::vector<std::string> slope_names;
  std::vector<double> slope_velocity, offset, offset_std;
  std::vector<Eigen::Index> slope_rows;
  Eigen::Index rows = 0;        ///< cruise samples fitted
  double relative_error = 0.0;  ///< ‖e‖/‖τ_J‖ on the cruise samples
  double residual_rms = 0.0;    ///< [N·m or N]
  /// The linear fit τ_J = a·sin q_J + b·cos q_J + c_s (a = k·cos q_off, b = k·sin q_off), with
  /// x = [a, b, c_1, …], HAC covariance over samples.
  Estimate estimate;
  std::vector<std::pair<std::string, std::string>> choices;  ///< what was decided and why
  std::vector<std::string> warnings;                         ///< named, human-readable
  /// The cruise samples, for plots: run index, q_J, measured and fitted τ_J.
  Eigen::VectorXi sample_run;
  Eigen::VectorXd sample_q, sample_tau, sample_fitted;
};

/// Fits the gravity torque of joint J, τ_J = k·sin(q_J + q_off) + c_s, on the constant-velocity
/// (cruise) parts of slope runs in which only joint J moves (seed 2 §3.2.1, eq. 23, Table 1):
/// on a cruise q̈ = 0, and for a joint moving alone M_JJ does not depend on q_J, so the
/// centripetal term vanishes and friction is a constant c_s per slope. Linear in
/// (a, b, c_s); k and q_off follow with the delta method. `runs`: prepared runs (preprocess()),
/// any number, each with one or both directions. Throws dynid::Error for a joint outside the
/// runs, a run whose velocity has no constant part (names the run and direction), no slope at
/// all, or slopes covering too little of q_J to separate k and q_off.
GravityExperimentResult fit_gravity_experiment(const std::vector<ProcessedRecord>& runs, int joint,
                                               const GravityExperimentOptions& options = {});

/// Gravity of one joint as a function of all q (seed 2 §3.2.1 generalised): slopes of joint J
/// recorded with the other joints held at a different pose in each run.
struct GravityPosesResult {
  int joint = 0;  ///< 0-based joint index J
  /// The base parameters of the gravity row J, τ_g,J(q) = Y_g,J(q)·θ_g: first-moment (and mass)
  /// combinations of the links J moves, named and regrouped as in compute_base_parameters()
  /// (`MX2R = MX2 + 0.4*M2`), in the order of `estimate.x`.
  std::vector<std::string> names, expressions;
  /// x = [θ_g, c_1, …, c_S, M_1, …, M_R] (c_s the constant of slope s, M_r the equivalent
  /// inertia of run r for the controller's q̈_J ripple on the cruise), HAC covariance, intervals.
  Estimate estimate;
  double confidence_level = 0.0;
  /// Per run: the pose of the joints (mean over its cruise samples; entry J is meaningless)
  /// [rad or m], and k·sin(q_J + q_off) at that pose with the delta-method std and interval
  /// half-widths, for comparison with fit_gravity_experiment() (seed 2 Table 1).
  std::vector<Eigen::VectorXd> pose;
  std::vector<double> k, q_off, k_std, q_off_std, k_ci_half_width, q_off_ci_half_width;
  /// Per slope (run, direction), as in GravityExperimentResult.
  std::vector<std::string> slope_names;
  std::vector<double> slope_velocity, offset, offset_std;
  std::vector<Eigen::Index> slope_rows;
  Eigen::Index rows = 0;        ///< cruise samples fitted
  double relative_error = 0.0;  ///< ‖e‖/‖τ_J‖ on the cruise samples
  double residual_rms = 0.0;    ///< [N·m or N]
  std::vector<std::pair<std::string, std::string>> choices;  ///< what was decided and why
  std::vector<std::string> warnings;                         ///< named, human-readable
};

/// Fits τ_J = Y_g,J(q)·θ_g + c_s + M_r·q̈_J on the cruise samples of slope runs of joint J in which
/// the other joints are held at a pose that changes between runs (seed 2 §3.2.1, eq. 23 generalised
/// to all q; docs/methods/experiments.md). Y_g,J is row J of the torque regressor at q̇ = q̈ = 0
/// restricted to its base columns (classify_columns() on random poses), c_s one constant per
/// slope (friction and the velocity terms of the held joints). Intervals: HAC over samples.
/// Throws dynid::Error for a joint outside the model, runs of another robot, a run without a
/// constant-velocity part, and runs whose poses do not determine θ_g (names the parameters
/// missing and how many poses are needed: one pose gives only k and q_off).
GravityPosesResult fit_gravity_poses(const Model& model, const std::vector<ProcessedRecord>& runs,
                                     int joint, const GravityExperimentOptions& options = {});

/// How many distinct poses of the joints other than J the runs hold (each run's mean position,
/// poses within 10·options.distinct_pose_tolerance [rad or m] counted as one): above 1, the
/// gravity of J can be fitted as a function of all q (fit_gravity_poses()). Throws dynid::Error
/// for a joint outside a run.
int count_distinct_poses(const std::vector<ProcessedRecord>& runs, int joint,
                         const GravityExperimentOptions& options = {});

/// The gravity torque of one joint that a gravity or decoupled experiment identified, τ_g,J(q), to
/// compensate it in a friction experiment as Bona & Curatella do (seed 2 §3.2: the friction runs
/// are compensated with the gravity identified from the slopes). Immutable after construction.
class JointGravityModel {
 public:
  /// τ_g,J = k·sin(q_J + q_off) (seed 2 eq. 23): fit_gravity_experiment(), fit_decoupled_joint().
  /// [N·m or N], [rad].
  static JointGravityModel sinusoid(int joint, double k, double q_off);
  /// τ_g,J = Y_g,J(q)·θ_g (fit_gravity_poses()): `names`/`values` its base parameters. Throws
  /// dynid::Error when the names are not the gravity base parameters of `joint` of `model` (a
  /// result of another robot or joint).
  static JointGravityModel poses(const Model& model, int joint,
                                 const std::vector<std::string>& names,
                                 const Eigen::VectorXd& values);
  int joint() const { return joint_; }  ///< 0-based joint index J
  /// τ_g,J at the positions q (n values) [N·m or N]. The poses form reuses one regressor workspace
  /// (no allocation per call), so one model must not be evaluated from several threads at once.
  double torque(const Eigen::VectorXd& q) const;

 private:
  struct Row;  // the gravity row's workspace and its weights over the link columns (poses form)
  int joint_ = 0;
  double k_ = 0.0, q_off_ = 0.0;
  std::shared_ptr<Row> row_;
};

}  // namespace dynid
