#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/equation_block.hpp"
#include "dynid/estimation/estimate.hpp"
#include "dynid/identification/cutoff_selection.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Motion of a force/torque sensor frame S over a run (or over a set of standing poses), every
/// vector expressed in S. Rows are samples; m×3 each.
struct SensorMotion {
  Eigen::VectorXd t;   ///< m time stamps [s], strictly increasing; empty for standing poses
  Eigen::MatrixXd w;   ///< angular velocity of S [rad/s]
  Eigen::MatrixXd dw;  ///< angular acceleration of S [rad/s²]
  Eigen::MatrixXd a;   ///< true linear acceleration of S's origin (gravity not subtracted) [m/s²]
  /// Linear velocity of S's origin [m/s], or empty: the integral model then integrates `a`.
  Eigen::MatrixXd v;
  Eigen::MatrixXd g;  ///< gravity in S, R_WSᵀ·g_W [m/s²]
};

/// Where the sensor sits: frame S fixed on link `link` (joint index) at pose (R_LS, p_LS) in that
/// link's frame.
struct SensorMount {
  int link = -1;                                       ///< joint index of the carrying link
  Eigen::Matrix3d R_LS = Eigen::Matrix3d::Identity();  ///< orientation of S in the link frame
  Eigen::Vector3d p_LS = Eigen::Vector3d::Zero();      ///< origin of S in the link frame [m]
};

/// Joint index of the link named `name` (Joint::link_name) or of the joint named `name`.
/// Throws dynid::UsageError naming the link and listing the model's link names.
int find_link(const Model& model, const std::string& name);

/// Rotation of the URDF roll-pitch-yaw convention, R = Rz(yaw)·Ry(pitch)·Rx(roll) [rad].
Eigen::Matrix3d roll_pitch_yaw(double roll, double pitch, double yaw);

/// Sensor-frame motion from the robot's kinematics: ω_S = R_LSᵀω_L, ω̇_S = R_LSᵀω̇_L,
/// p̈_S = R_LSᵀ(a_L + ω̇_L×p_LS + ω_L×(ω_L×p_LS)), v_S = R_LSᵀ(v_L + ω_L×p_LS),
/// g_S = (R_WL·R_LS)ᵀ·model.gravity (seed 1 eq. 28's p̈, ω, ω̇ and ⁰_P R g). record: t (m, may be
/// empty for standing poses), q, dq, ddq (m×n each; dq and ddq may be empty = standing poses).
/// Throws dynid::Error for size mismatches, a link index out of range, or a zero gravity.
SensorMotion sensor_motion_from_joints(const Model& model, const JointRecord& record,
                                       const SensorMount& mount);

/// A joint-side run with its wrench, prepared for the load equations.
struct PreparedLoadRun {
  JointRecord record;      ///< filtered, differentiated, trimmed, decimated (tau unused, zero)
  Eigen::MatrixXd wrench;  ///< m×6, the same zero-phase filter, trim and decimation as q
};

/// preprocess() (identify's signal processing) on t, q [, dq, ddq] of `record`, and the same
/// filter, trim and decimation on the wrench (m×6), so that kinematics and wrench keep one delay
/// and bandwidth (Gautier's parallel filtering, as for q and tau). Choices go to `choices`.
/// Throws dynid::Error as preprocess(), or for a wrench whose row count differs from q's.
PreparedLoadRun prepare_load_run(const JointRecord& record,
                                 const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                                 const SignalOptions& options,
                                 std::vector<std::pair<std::string, std::string>>& choices);

/// The sensor's own log: orientation and optional rates (columns qx qy qz qw wx wy wz dwx dwy dwz
/// ax ay az of `dynid payload`).
struct OrientationLog {
  Eigen::VectorXd t;           ///< m time stamps [s]; empty for standing poses
  Eigen::MatrixXd quaternion;  ///< m×4 unit quaternion (x, y, z, w) of S in the base frame
  Eigen::MatrixXd w;           ///< m×3 angular velocity in S [rad/s], or empty (derived)
  Eigen::MatrixXd dw;          ///< m×3 angular acceleration in S [rad/s²], or empty (derived)
  Eigen::MatrixXd a;           ///< m×3 linear acceleration of S's origin in S [m/s²], or empty
};

/// Sensor-frame motion from an orientation log: g_S = R_WSᵀ·gravity; a missing ω from the
/// quaternion's central difference, ω_S = 2·vec(q̄ ⊗ q̇) (sign flips between rows removed first);
/// a missing ω̇ from ω by central differences; a missing p̈ is taken as zero (a sensor that only
/// turns about its origin) and said so in `choices`. Standing poses (empty t) have ω = ω̇ = p̈ = 0.
/// Throws dynid::Error: a quaternion whose norm is not 1 within 1e-3 (names the row), sizes, a
/// zero or non-finite gravity.
SensorMotion sensor_motion_from_orientation(
    const OrientationLog& log, const Eigen::Vector3d& gravity,
    std::vector<std::pair<std::string, std::string>>& choices);

/// Which equations of the load (seed 1 §III).
enum class LoadModelKind {
  kDifferential,  ///< W = K·Φ per sample (eq. 28); needs ω̇ and p̈
  kIntegral,      ///< ∫W dt = ∫K dt·Φ per window (eqs. 29–31); no accelerations needed
  kStatic         ///< standing poses: W = K(0, 0, 0, g)·Φ; only m and mc (and biases)
};

/// Options of load_equations (Ceres style).
struct LoadEquationOptions {
  LoadModelKind model = LoadModelKind::kDifferential;  ///< which equations
  /// Integral model: window length [s]; consecutive, non-overlapping windows. 0.2 s keeps ≥ 5
  /// windows in a 1 s move while integrating out sensor noise over tens of samples at ≥ 100 Hz.
  double interval = 0.2;
  /// Add the six constant sensor offsets fx0..mz0 (reading = true reading + offset) as columns.
  bool bias = false;
  /// +1: the columns are the force and moment the load exerts on the sensor (drivers' convention,
  /// a load at rest reads +m·g); −1: the ones the sensor exerts on the load (seed 1's F, N).
  double wrench_sign = 1.0;
  /// Which scalar equations of eq. 28/29 enter, in the order fx fy fz mx my mz: seed 1 §VI-B found
  /// the integral model better on the components the motion excites. Forces determine m and mc,
  /// moments mc and the inertias; what the chosen rows leave undetermined is named not_excited.
  std::array<bool, 6> components = {true, true, true, true, true, true};
};

/// The --components list "fx,fy,mz" (any order, no repeats) as LoadEquationOptions::components.
/// Throws dynid::UsageError naming `flag` for an empty list, a repeat or an unknown name.
std::array<bool, 6> load_components_from_text(const std::string& list, const std::string& flag);

/// Names of the load parameters in column order: m mcx mcy mcz [Ixx Ixy Ixz Iyy Iyz Izz, unless
/// static] [fx0 fy0 fz0 mx0 my0 mz0 with bias, those of the chosen components].
std::vector<std::string> load_parameter_names(const LoadEquationOptions& options);

/// The load's equations as an EquationBlock: y = −wrench_sign·reading (seed 1's W), W = K (eq. 28)
/// per sample, ∫K dt per window (eqs. 29–31, trapezoidal rule, ∫K dt = Σ K(ω, 0, ω×v, g)·dt +
/// K(0, Δω, Δv, 0)), or K's m/mc columns for standing poses; bias columns −wrench_sign·I₆ (·T for
/// a window). One row per chosen wrench component and sample/window; group = component (the
/// chosen ones of fx fy fz mx my mz, in that order), sample = sample/window index, t = its time
/// (window end). wrench: m×6 [N, N·m], sensor frame. Throws dynid::Error: size mismatch, NaN/Inf,
/// missing t or ω̇/p̈ where the model needs them, an interval shorter than one sample step or giving
/// fewer windows than parameters need, fewer standing poses than the static model needs (2, or 3
/// with biases).
EquationBlock load_equations(const SensorMotion& motion,
                             const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                             const LoadEquationOptions& options);

/// The automatic cut-off of a force/torque sensor run on the robot (`dynid payload --robot`):
/// identify's held-out rule (select_cutoff_held_out()) with the load equations, so that the same
/// mechanism chooses every cut-off (issue 25 item 4). Each candidate processes the run and its
/// wrench alike (prepare_load_run()), builds the sensor motion and the equations, fits the load on
/// alternate blocks and predicts the wrench of the others. The load's ω×(ω×c) and ω̇ terms are
/// products and derivatives of the motion, so a cut-off near the motion's band biases the centre
/// of mass and the inertias: the spectral rule alone chose 1.83 Hz for a 1 Hz motion, and the
/// inertias came out 12–15× outside an acceptable error. `signal` with a given cut-off or
/// without filtering is returned unchanged. Throws as prepare_load_run().
CutoffSelection select_load_cutoff(const Model& model, const SensorMount& mount,
                                   const JointRecord& record,
                                   const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                                   const SignalOptions& signal,
                                   const LoadEquationOptions& equations,
                                   const CutoffSelectionOptions& selection = {});

/// prepare_load_run() of a sensor run on the robot with the cut-off of select_load_cutoff() when
/// `signal` asks for the automatic one, its reason in `choices` (the one preparation `dynid
/// payload --sensor-link` and Python's payload() share). Throws as both.
PreparedLoadRun prepare_sensor_run(const Model& model, const SensorMount& mount,
                                   const JointRecord& record,
                                   const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                                   const SignalOptions& signal,
                                   const LoadEquationOptions& equations,
                                   std::vector<std::pair<std::string, std::string>>& choices);

/// Estimator of identify_load.
enum class LoadEstimator {
  kOls,  ///< ordinary least squares (QR)
  kWls,  ///< Gautier's two-step weighted least squares, one noise variance per wrench component
  kRls   ///< U-D-Uᵀ recursive least squares (seed 1 eqs. 36–37, Agee–Turner/Bierman)
};

/// Options of identify_load (Ceres style).
struct LoadIdentificationOptions {
  LoadEstimator estimator = LoadEstimator::kOls;  ///< batch or recursive
  double confidence_level = 0.999;                ///< Student-t interval level
  bool record_history = false;                    ///< RLS: keep the estimate after every row
  /// Replace the white covariance by the Newey–West sandwich over samples
  /// (apply_hac_covariance): needed when the wrench was low-pass filtered, which correlates the
  /// residuals of neighbouring samples and makes white intervals too narrow.
  bool hac_covariance = false;
};

/// Physical reading of the ten load parameters about the sensor origin.
struct LoadPhysics {
  double mass = 0.0;                                      ///< m [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();          ///< c = mc/m [m], sensor frame
  Eigen::Matrix3d inertia_com = Eigen::Matrix3d::Zero();  ///< I_C (seed 1 eq. 24) [kg·m²]
  bool consistent = false;  ///< m > 0, I_C positive definite, triangle inequalities
  std::string violated;     ///< what breaks the first violated condition, empty when consistent
};

/// c = mc/m and I_C = I_P − m[(cᵀc)·1 − c·cᵀ] (seed 1 eq. 24) from
/// phi = [m mcx mcy mcz Ixx Ixy Ixz Iyy Iyz Izz]; with `with_inertia` false only m and c are
/// checked. Never throws; m ≤ 0 gives consistent = false and c = 0.
LoadPhysics load_physics(const Eigen::Ref<const Eigen::VectorXd>& phi, bool with_inertia);

/// Result of identify_load.
struct LoadIdentificationResult {
  std::vector<std::string> names;  ///< parameter names (load_parameter_names)
  Estimate estimate;               ///< values, σ, intervals, residual statistics
  LoadPhysics physics;             ///< from the estimate
  /// Parameters the data do not determine: unidentifiable (W rank deficient), or an inertia whose
  /// σ exceeds 30 % of the load's rotational scale max(m|c|², max_i |I_ii| − 3σ_ii) (slow motions).
  std::vector<std::string> not_excited;
  Eigen::MatrixXd history;  ///< RLS with record_history: rows × parameters estimates
};

/// Estimates the load parameters from a block built by load_equations (OLS or U-D RLS), with the
/// physical reading and the not-excited list. Throws dynid::Error: fewer rows than columns, NaN;
/// m or a first moment unidentifiable (gravity never changed direction in the sensor frame);
/// a mass whose interval contains 0 (no load on the sensor) or that is significantly negative
/// (the wrench logged with the other sign: names --wrench-sign).
LoadIdentificationResult identify_load(const EquationBlock& block,
                                       const LoadIdentificationOptions& options);

/// Where the load parameters from joint torques are expressed: about the origin of frame F, in
/// F's axes, F fixed on the link at (R_LF, p_LF) in the link frame (identity: the link frame).
struct LoadFrame {
  Eigen::Matrix3d R_LF = Eigen::Matrix3d::Identity();  ///< orientation of F in the link frame
  Eigen::Vector3d p_LF = Eigen::Vector3d::Zero();      ///< origin of F in the link frame [m]
};

/// A load on link `link` from joint torques alone (no sensor): the loaded run's torques are
/// Y(q, q̇, q̈)·[θ; Φ_L] with Φ_L entering like the link's own standard parameters (the load
/// adds to the link's inertia), the unloaded run's are Y·θ; both runs are stacked and solved
/// together, [Y_loaded, Y_link·T; Y_unloaded, 0]·[θ; Φ_F] = [τ_loaded; τ_unloaded], where T maps
/// the load's parameters about F to those about the link origin (transform_link_params, linear).
/// Φ_F is reported in load order (m mcx … Izz). The joint torques do not determine every load
/// parameter (a parameter the arm's motion cannot separate from the robot's own, e.g. the mass of
/// a load on the last link of a 6R wrist): those are listed in not_excited and their σ is +inf;
/// the physical reading needs all ten. `layout`: the robot's friction/armature columns. Runs:
/// processed records (preprocess()) with tau. Options as identify_load (WLS groups = joints; HAC
/// over samples of each run). Throws dynid::Error for a link out of range, sizes, fewer rows than
/// columns; as identify_load for the mass (when determined).
LoadIdentificationResult identify_load_from_torques(const Model& model, int link,
                                                    const LoadFrame& frame,
                                                    const ParameterLayout& layout,
                                                    const JointRecord& loaded,
                                                    const JointRecord& unloaded,
                                                    const LoadIdentificationOptions& options);

/// A load on link `link` from the torque an identified model of the unloaded robot does not
/// explain (issue 12 item 3, a `dynid identify` result as reference): τ_loaded − τ̂ = Y_link·T·Φ_F,
/// with τ̂ the model's prediction on the loaded run (validate_torques()'s `predicted` on the same
/// processed record). Only the ten load columns are fitted; the reference's own uncertainty is not
/// propagated (its σ is small when it was identified on a long run; docs/methods/load.md). Rows
/// with |q̇_j| below zero_velocity_threshold(j) are left out as identify() left them out (empty:
/// every row). loaded: processed record (t, q, dq, ddq, tau; m×n); predicted: m×n [N·m or N].
/// Parameters the torques do not determine are in not_excited with σ = +inf. Throws
/// dynid::Error for sizes, non-finite values, a link out of range, fewer rows than columns; as
/// identify_load for the mass (when determined).
LoadIdentificationResult identify_load_from_unexplained_torques(
    const Model& model, int link, const LoadFrame& frame, const JointRecord& loaded,
    const Eigen::Ref<const Eigen::MatrixXd>& predicted,
    const Eigen::Ref<const Eigen::VectorXd>& zero_velocity_threshold,
    const LoadIdentificationOptions& options);

}  // namespace dynid
