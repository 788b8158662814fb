#pragma once

// identify(): the pipeline of docs/design.md §8 over one or several runs (prepare → equations →
// stack → estimate), its options and its result.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/closed_loop/closed_loop_options.hpp"
#include "dynid/common/progress.hpp"
#include "dynid/estimation/estimate.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/identification/data_diagnostics.hpp"
#include "dynid/identification/integral_options.hpp"
#include "dynid/identification/known_friction.hpp"
#include "dynid/identification/outlier_options.hpp"
#include "dynid/identification/pipeline.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// Which equations identify() builds from each prepared run (docs/design.md §8, "equations").
enum class IdentificationModel {
  kDifferential,  ///< τ = Y(q, q̇, q̈)·θ per joint and sample (seed 1 eq. 5, seed 2 eq. 9)
  kIntegral       ///< ∫τᵀq̇ dt = ΔH·θ + friction work per interval (seed 1 eqs. 15–17)
};

/// Options of identify().
struct IdentifyOptions {
  ParameterLayout layout = ParameterLayout::full();  ///< link + per-joint columns to identify
  bool coupling = true;  ///< add the coupled-motor columns when the transmission couples joints
  IdentificationEstimator estimator = IdentificationEstimator::kOls;  ///< batch or recursive
  double confidence_level = 0.999;  ///< Student-t interval level (seed 2 Table 3)
  /// Bartlett window (samples) of the HAC covariance behind std/ci_*; −1 = automatic (Andrews).
  int hac_bandwidth = -1;
  SignalOptions signal;  ///< filtering, derivatives, decimation, sample removal
  /// The equations: differential (default) or integral. The integral model needs no q̈ and no
  /// zero-velocity rule (|q̇| is continuous); an automatic cut-off becomes
  /// integral_signal_options()'s 10 Hz and an automatic decimation 1 (the power is integrated at
  /// the full rate).
  IdentificationModel model = IdentificationModel::kDifferential;
  IntegralOptions integral;   ///< intervals and quadrature of the integral model
  BaseParameterOptions base;  ///< base-parameter computation (layout is overwritten)
  OutlierOptions outliers;    ///< gross torque outliers: report or drop (outliers.hpp)
  /// Friction identified before, subtracted from the measured torque of the differential model
  /// (seed 2 §3.4); give a layout without those friction columns. Empty = none.
  KnownFriction known_friction;
  /// With the RLS estimator: keep the estimate and σ after every equation (history_* of the
  /// result; memory grows with the rows).
  bool record_history = false;
  /// Persistent-excitation window ρ (equations) of the RLS excitation report; 0 = max(10 ×
  /// parameters, equations/10).
  int excitation_window = 0;
  /// Closed-loop preparation (projection, spectral) instead of filtering; needs the references
  /// (identify() with ReferenceRecord). `signal` then only gives the torque time offset.
  ClosedLoopIdOptions closed_loop;
  /// With the ML estimator: the raw sensor noise (empty entries estimated from the data).
  SensorNoise noise;
  /// Told how the long stages get on (today the ML iterations; common/progress.hpp); may be empty.
  ProgressCallback progress;
};

/// One run of a (possibly several-run) identification.
struct RunSummary {
  std::string file;             ///< where the run came from (set by the caller; may be empty)
  Eigen::Index samples = 0;     ///< samples after processing
  Eigen::Index rows = 0;        ///< equations the run contributed
  double relative_error = 0.0;  ///< ‖e‖/‖y‖ over the run's equations, at the joint estimate
  Eigen::VectorXd zero_velocity_threshold;  ///< per joint, as for the whole result
};

/// Everything identify() found, ready to be written as the JSON of docs/design.md §4.
struct IdentificationResult {
  std::vector<std::string> names;        ///< base parameter names (ZZ1R, …, Fv1, …)
  std::vector<std::string> expressions;  ///< regrouping expressions, one per base parameter
  /// Per name, the name reported: names[i] + "R" when these data regroup into it a parameter of
  /// data_regrouped (Fc2R = Fc2 + Fcm3, as the base set names its regroupings), else names[i].
  /// names[i] stays the identifier every lookup in base.names uses. Empty = names.
  std::vector<std::string> labels;
  std::vector<std::string> unidentifiable;  ///< standard parameters with no effect at all
  /// Per name, the nominal model's value of that base parameter (nominal_base_values()); empty
  /// where the model has none (a per-joint term the model gives as 0, e.g. friction of a URDF).
  std::vector<std::optional<double>> nominal;
  /// Joints whose velocities move together in every run (find_lockstep_joints()), with the base
  /// parameters that leaves undetermined; each is also a warning.
  std::vector<LockstepJoints> lockstep;
  Estimate estimate;                     ///< values, σ, %σ, CI, residual statistics, summary
  int rank = 0;                          ///< base parameters (model rank)
  double condition_number = 0.0;         ///< of the (weighted) base regressor on these data
  Eigen::Index samples = 0;              ///< samples used after processing
  Eigen::Index rows = 0;                 ///< equations used (after zero-velocity removal)
  Eigen::VectorXd residual_rms;          ///< per joint [N·m]
  Eigen::VectorXd joint_relative_error;  ///< per joint ‖e_j‖/‖tau_j‖
  double relative_error = 0.0;           ///< ‖tau − Ŷθ̂‖/‖tau‖ over the rows used
  /// Per joint, lag-1 autocorrelation of the residuals over consecutive samples used (in-memory
  /// identify only; a named warning above 0.5: the intervals assume white residuals).
  Eigen::VectorXd residual_autocorrelation;
  std::vector<std::string> warnings;                         ///< named, human-readable
  std::vector<std::pair<std::string, std::string>> choices;  ///< every processing choice made
  /// Per joint, the |dq_j| below which rows were left out of the fit [rad/s or m/s]; zeros when
  /// none were (validate_torques reuses these, so a validation compares the same kind of rows).
  Eigen::VectorXd zero_velocity_threshold;
  /// Per joint, the transition velocity v_c of the smooth Coulomb law the fit used [rad/s or m/s]
  /// (ProcessedRecord::coulomb_width, the largest over runs); empty without expected-sign columns.
  /// validate_torques predicts rest with the same law.
  Eigen::VectorXd coulomb_width;
  BaseParameters base;           ///< the base set on which the estimate lives
  ProcessedRecord processed;     ///< the data as used (the first run's)
  std::vector<RunSummary> runs;  ///< per run, in the order given
  /// Rank of the stacked base regressor on these data (= rank when the data excite every base
  /// parameter); names/estimate hold only the data-identifiable ones.
  int data_rank = 0;
  std::vector<std::string> not_excited;  ///< base parameters the data do not determine
  /// Of not_excited: those whose column is a combination of the estimated ones to round-off on
  /// these data (DataIdentifiability::regrouped), regrouped exactly into the parameters that
  /// absorb them (labels) rather than left undetermined by the noise.
  std::vector<std::string> data_regrouped;
  /// names.size() × not_excited.size(): on these data each estimate is its base parameter plus
  /// data_regrouping·θ(not_excited) (the data cannot separate them); its expression says so.
  Eigen::MatrixXd data_regrouping;
  bool has_excitation = false;   ///< excitation is filled (RLS)
  ExcitationSummary excitation;  ///< persistent excitation (seed 1 eq. 38)
  /// With IdentifyOptions::record_history and RLS: per equation its time [s], the estimate and σ.
  Eigen::VectorXd history_t;
  Eigen::MatrixXd history_x, history_std;
  /// With a closed-loop preparation: per run, what it chose and found.
  std::vector<ClosedLoopReport> closed_loop;
  /// With a closed-loop preparation, where the intervals' noise comes from: "projected_residual"
  /// (the projected equations' own residual) or "torque_remainder" (no degrees of freedom left
  /// there: the torque outside the projected span, projected_statistics()); empty otherwise.
  std::string interval_source;
};

/// What a result's estimates stand for, given a value of every base parameter (base_values, in
/// result.base.names order, e.g. the true base parameters of a simulation): per name of
/// result.names, θ_b[name] + Σ_j data_regrouping(i, j)·θ_b[not_excited[j]]. With every base
/// parameter excited that is θ_b itself; with some not excited it is the truth each kept estimate
/// is to be compared with. Throws dynid::Error when base_values does not have one value per base
/// parameter or the result's names, not_excited and data_regrouping do not match.
Eigen::VectorXd estimated_base_values(const IdentificationResult& result,
                                      const Eigen::VectorXd& base_values);

/// Identifies the base parameters of `model` from a joint-side record: preprocess, stack the
/// regressor (tau = Y·theta, seed 1 eq. 5 / seed 2 eq. 9), keep the base columns (Gautier–Khalil),
/// estimate by OLS, Gautier's WLS or U-D RLS (seed 1 eqs. 36–37), and report statistics.
/// Throws dynid::Error for inconsistent sizes, NaN, too few samples.
IdentificationResult identify(const Model& model, const JointRecord& record,
                              const IdentifyOptions& options = {});

/// identify() of several runs together (issue 11 item 2): each run is screened and preprocessed
/// on its own (its own rate, filter edges, derivatives, zero-velocity thresholds), its equations
/// built, and the blocks stacked (stack_equations) before the base columns and the estimate; the
/// result's runs[] report each run. Base parameters the stacked data do not excite (data rank
/// below the model rank, data_identifiability) are named in not_excited and not estimated.
/// Throws dynid::Error for no run and as identify().
IdentificationResult identify(const Model& model, const std::vector<JointRecord>& runs,
                              const IdentifyOptions& options = {});

/// identify() of closed-loop runs with their references (one per run, or none without
/// options.closed_loop): each run prepared by prepare_closed_loop() (closed_loop.hpp) instead of
/// filtering, its equations projected alike (project_equations, no zero-velocity removal), and
/// the intervals counted on the projected dimensions (projected_statistics). With kMl (direct
/// runs only): maximum_likelihood() from the OLS estimate, noise from options.noise or the data.
/// Throws dynid::Error for a reference count that does not match, ML with a closed-loop
/// preparation, and as identify().
IdentificationResult identify(const Model& model, const std::vector<JointRecord>& runs,
                              const std::vector<ReferenceRecord>& references,
                              const IdentifyOptions& options);

}  // namespace dynid
