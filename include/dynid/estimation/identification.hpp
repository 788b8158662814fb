#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/common/progress.hpp"
#include "dynid/estimation/closed_loop_options.hpp"
#include "dynid/estimation/estimate.hpp"
#include "dynid/estimation/integral_options.hpp"
#include "dynid/estimation/known_friction.hpp"
#include "dynid/estimation/outlier_options.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/signal/lowpass_design.hpp"

namespace dynid {

/// A recorded run on the joint side: time, positions, optional derivatives, torques.
struct JointRecord {
  Eigen::VectorXd t;    ///< m time stamps [s], strictly increasing
  Eigen::MatrixXd q;    ///< m × n [rad or m]
  Eigen::MatrixXd dq;   ///< m × n or empty: derived from q when absent
  Eigen::MatrixXd ddq;  ///< m × n or empty: derived from dq when absent
  Eigen::MatrixXd tau;  ///< m × n joint torques [N·m or N]
};

/// Signal processing before estimation (issue 4; seed 2 §3.4, Gautier's parallel filtering).
/// Negative / zero "auto" values are replaced by defaults that the result reports back.
struct SignalOptions {
  bool filter =
      true;  ///< zero-phase low-pass of q and tau with the same filter (parallel filtering)
  LowpassFamily family = LowpassFamily::kButterworth;  ///< filter prototype
  int order = 4;                                       ///< filter order
  /// Low-pass cut-off [Hz]; 0 = auto: choose_cutoff() (signal/noise_floor.hpp), 1.5 × the upper
  /// end of the band where the position spectrum stands 20 dB above its noise floor, in
  /// [1 Hz, min(20 Hz, rate/10)].
  double cutoff_hz = 0.0;
  double ripple_db = 0.5;  ///< Chebyshev I passband ripple
  int decimate = 0;        ///< keep every k-th sample; 0 = auto: rate/(10·cutoff), ≥ 1
  int trim = -1;  ///< samples dropped at each end after filtering; −1 = auto: 3·rate/cutoff
  bool savitzky_golay =
      false;  ///< differentiate with Savitzky–Golay instead of central differences
  /// Coulomb friction is undefined near dq = 0: rows of joint j with |dq_j| below the threshold are
  /// removed. One value = all joints; else n values. Empty = auto: threshold_j =
  /// max(zero_velocity_fraction·max|dq_j|, zero_velocity_noise_multiple·σ_dq,j) (real joints leave
  /// the Coulomb law below a physical velocity band; below the noise the sign of dq is unknown),
  /// and the Coulomb columns are the filtered expected sign (as with filter_coulomb_columns): with
  /// a low cut-off the filtered torque's smeared Coulomb step otherwise biases Fv high and Fc low
  /// (docs/methods/estimation.md, "Friction near zero velocity").
  std::vector<double> zero_velocity;
  /// Automatic zero-velocity rule: fraction of max|dq_j| of the processed record (the band where
  /// real joint friction is not Fc·sign(dq): pre-sliding, Stribeck; 1 % matches FIGAROH's TX40).
  double zero_velocity_fraction = 0.01;
  /// Automatic zero-velocity rule: multiple k of the processed velocity's noise std σ_dq.
  double zero_velocity_noise_multiple = 3.0;
  /// The torque logged at time stamp t acts at t + torque_time_offset [s]; the torques are
  /// re-interpolated (linearly) onto the position time stamps before filtering. A controller that
  /// logs the command it then holds for one period (zero-order hold, as `dynid simulate` does)
  /// needs +T/2: central differences centre q̈ on the sample, the held torque half a period later.
  /// A torque sensor lagging by d needs −d. 0 = as logged.
  double torque_time_offset = 0.0;
  /// Filter the Coulomb columns of the regressor (sign(dq), or [dq>0] and −[dq<0]; with a known
  /// velocity noise σ_dq the expected sign erf(dq/(√2·σ_dq)) and its halves) with the same
  /// zero-phase filter as tau, from the full-rate velocity (Gautier's parallel filtering applied to
  /// the one discontinuous column): the filtered torque's smeared Coulomb step at a velocity
  /// reversal is then matched by the model instead of biasing Fv and Fc. Only with `filter`;
  /// coupled-motor Coulomb columns stay unfiltered.
  bool filter_coulomb_columns = false;
};

/// Per-joint zero-velocity thresholds [rad/s or m/s] from SignalOptions::zero_velocity: one value
/// for all n joints, or n values; empty gives an empty vector (the caller's automatic rule).
/// Throws dynid::UsageError for any other count.
Eigen::VectorXd given_zero_velocity(const std::vector<double>& zero_velocity, int n);

/// kMl: maximum likelihood with errors in variables (maximum_likelihood.hpp), from the OLS start.
enum class IdentificationEstimator { kOls, kWls, kRls, kMl };

/// Which equations identify() builds from each prepared run (DESIGN.md §8, "equations").
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

/// Persistent excitation of the equations (seed 1 eq. 38), reported with the RLS estimator.
struct ExcitationSummary {
  int window = 0;               ///< ρ, equations per window
  double min_eigenvalue = 0.0;  ///< α over all windows (column-scaled regressor)
  double max_eigenvalue = 0.0;  ///< β over all windows
  double holds_from_t = 0.0;    ///< time [s] from which the condition holds; NaN if never
  int windows = 0;              ///< windows evaluated
};

/// The preprocessed data actually used for estimation (useful for plots and validation).
struct ProcessedRecord {
  JointRecord record;    ///< filtered, differentiated, trimmed and decimated
  double rate_hz = 0.0;  ///< sample rate of `record`
  /// With SignalOptions::filter_coulomb_columns: [dq_j > 0] and [dq_j < 0] at the full rate,
  /// filtered like tau, trimmed and decimated like `record` (m × n each); else empty.
  Eigen::MatrixXd moving_positive, moving_negative;
  double cutoff_hz = 0.0;  ///< low-pass cut-off used [Hz]; 0 without filter
  int trim = 0;            ///< samples dropped at each end after filtering (resolved)
  int decimate = 1;        ///< every decimate-th sample kept (resolved)
  /// Per joint, std of the white position noise floor of the input (position_noise_floor) and of
  /// the resulting noise on the processed velocity [rad/s or m/s]; 0 when not measurable.
  Eigen::VectorXd position_noise_std, velocity_noise_std;
};

/// Sample-major regressor of a processed record (stacked_regressor), with the Coulomb columns
/// replaced by their filtered versions when the record carries them (filter_coulomb_columns).
Eigen::MatrixXd processed_regressor(const Model& model, const ParameterLayout& layout,
                                    bool coupling, const ProcessedRecord& processed);

/// Everything identify() found, ready to be written as the JSON of DESIGN.md §4.
struct IdentificationResult {
  std::vector<std::string> names;           ///< base parameter names (ZZ1R, …, Fv1, …)
  std::vector<std::string> expressions;     ///< regrouping expressions, one per base parameter
  std::vector<std::string> unidentifiable;  ///< standard parameters with no effect at all
  Estimate estimate;                        ///< values, σ, %σ, CI, residual statistics, summary
  int rank = 0;                             ///< base parameters (model rank)
  double condition_number = 0.0;            ///< of the (weighted) base regressor on these data
  Eigen::Index samples = 0;                 ///< samples used after processing
  Eigen::Index rows = 0;                    ///< equations used (after zero-velocity removal)
  Eigen::VectorXd residual_rms;             ///< per joint [N·m]
  Eigen::VectorXd joint_relative_error;     ///< per joint ‖e_j‖/‖tau_j‖
  double relative_error = 0.0;              ///< ‖tau − Ŷθ̂‖/‖tau‖ over the rows used
  /// Per joint, lag-1 autocorrelation of the residuals over consecutive samples used (in-memory
  /// identify only; a named warning above 0.5: the intervals assume white residuals).
  Eigen::VectorXd residual_autocorrelation;
  std::vector<std::string> warnings;                         ///< named, human-readable
  std::vector<std::pair<std::string, std::string>> choices;  ///< every processing choice made
  /// Per joint, the |dq_j| below which rows were left out of the fit [rad/s or m/s]; zeros when
  /// none were (validate_torques reuses these, so a validation compares the same kind of rows).
  Eigen::VectorXd zero_velocity_threshold;
  BaseParameters base;           ///< the base set on which the estimate lives
  ProcessedRecord processed;     ///< the data as used (the first run's)
  std::vector<RunSummary> runs;  ///< per run, in the order given
  /// Rank of the stacked base regressor on these data (= rank when the data excite every base
  /// parameter); names/estimate hold only the data-identifiable ones.
  int data_rank = 0;
  std::vector<std::string> not_excited;  ///< base parameters the data do not determine
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
};

/// Sample-major stacked regressor of the layout plus coupling columns for a record:
/// rows k·n … k·n+n−1 are sample k. Size (m·n) × (layout.columns(n) + coupling_columns(model)).
Eigen::MatrixXd stacked_regressor(const Model& model, const ParameterLayout& layout, bool coupling,
                                  const JointRecord& record);

/// Names of the columns of stacked_regressor.
std::vector<std::string> stacked_regressor_names(const Model& model, const ParameterLayout& layout,
                                                 bool coupling);

/// Filters, differentiates, trims and decimates a record as SignalOptions says; fills in the auto
/// choices (written to `choices`). Throws dynid::Error for too few samples or bad time stamps.
ProcessedRecord preprocess(const JointRecord& record, const SignalOptions& options,
                           std::vector<std::pair<std::string, std::string>>& choices);

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

/// Per-joint prediction error of identified base parameters on another record (dynid validate).
/// Two figures: over every row (the headline), and over the rows identify() fits (near-still rows
/// of a Coulomb model left out: their sign(dq) is noise).
struct ValidationResult {
  Eigen::VectorXd rms;              ///< per joint [N·m], on the rows compared
  Eigen::VectorXd relative_error;   ///< per joint ‖e_j‖/‖tau_j‖, on the rows compared
  double relative_error_all = 0.0;  ///< ‖e‖/‖tau‖ over all joints, on the rows compared
  /// ‖e‖/‖tau‖ over every sample, near-zero-velocity rows included.
  double relative_error_all_rows = 0.0;
  Eigen::VectorXd rms_all_rows;                   ///< per joint [N·m], every sample
  Eigen::VectorXd relative_error_all_rows_joint;  ///< per joint ‖e_j‖/‖tau_j‖, every sample
  Eigen::VectorXd zero_velocity_threshold;  ///< per joint, the |dq_j| below which rows are left out
  Eigen::VectorXi joint_rows_excluded;      ///< per joint, rows left out by that threshold
  Eigen::Index samples = 0;                 ///< samples after preprocessing
  Eigen::Index rows = 0;           ///< joint equations compared (samples × joints − excluded)
  Eigen::Index rows_excluded = 0;  ///< near-zero-velocity rows left out, as identify() does
  std::vector<std::pair<std::string, std::string>> choices;  ///< processing choices made
  ProcessedRecord processed;
  Eigen::MatrixXd predicted;  ///< samples × n predicted torques
};

/// Predicts the torques of `record` with base parameters `values` named `names` (as identify()
/// wrote them) and compares. The record is preprocessed and, with Coulomb friction in the layout,
/// rows with |dq_j| below the zero-velocity threshold are left out of the statistics exactly as
/// identify() leaves them out of the fit (so validating on the identification run reproduces its
/// relative error); relative_error_all_rows keeps them. The thresholds are options.signal
/// .zero_velocity (give the identification's IdentificationResult::zero_velocity_threshold), else
/// the automatic rule of identify() on this record. A name that is not a column of the model
/// and layout is an Error naming the parameter.
/// `not_excited` are the base parameters the identification data did not determine
/// (IdentificationResult::not_excited): the estimates then hold data regroupings that predict only
/// motions which leave those directions unexcited too. When this record excites a direction the
/// result does not determine (the data rank of its determined and undetermined columns together
/// exceeds that of the determined ones), the prediction would be a wrong number: Error naming the
/// parameters.
ValidationResult validate_torques(const Model& model, const JointRecord& record,
                                  const std::vector<std::string>& names,
                                  const Eigen::VectorXd& values, const IdentifyOptions& options,
                                  const std::vector<std::string>& not_excited = {});

/// A Model whose dynamics are those of identified base parameters: the dependent standard
/// parameters theta_2 keep the nominal model's values and theta_1 = theta_b − K_d·theta_2
/// (Gautier–Khalil), so tau = Y·theta equals the identified base model exactly; the unidentifiable
/// parameters keep their nominal values. Friction/armature columns go to Joint::friction
/// (asymmetric pairs as mean and asymmetry, JointFriction::Fva/Fca; coupled-motor columns cannot be
/// represented and are dropped; terms that are not in options.layout keep their nominal values).
/// The individual links need not be physically consistent (only theta_b is identified), so the
/// model is not finalize()d. Throws dynid::Error for a name that is not a base parameter of the
/// model with options.layout.
Model identified_model(const Model& nominal, const std::vector<std::string>& names,
                       const Eigen::VectorXd& values, const IdentifyOptions& options);

}  // namespace dynid
