#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/equation_block.hpp"
#include "dynid/estimation/estimate.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/identification/record.hpp"

namespace dynid {

/// kMl: maximum likelihood with errors in variables (maximum_likelihood.hpp), from the OLS start.
enum class IdentificationEstimator { kOls, kWls, kRls, kMl };

/// Persistent excitation of the equations (seed 1 eq. 38), reported with the RLS estimator.
struct ExcitationSummary {
  int window = 0;               ///< ρ, equations per window
  double min_eigenvalue = 0.0;  ///< α over all windows (column-scaled regressor)
  double max_eigenvalue = 0.0;  ///< β over all windows
  double holds_from_t = 0.0;    ///< time [s] from which the condition holds; NaN if never
  int windows = 0;              ///< windows evaluated
};

/// The equations stage of the differential model (docs/design.md §8): one row per joint and sample
/// of a processed run, tau_j(k) = Y_j(q, dq, ddq)(k)·θ (seed 1 eq. 5, seed 2 eq. 9), over the
/// standard columns stacked_regressor_names(model, layout, coupling), with the Coulomb columns
/// filtered when the record carries them (processed_regressor). With Coulomb friction in the
/// layout, rows with |dq_j(k)| < zero_velocity_threshold[j] are left out (sign(dq) is noise there).
/// group = joint (group_names = joint names), sample = k, t = the sample's time [s].
/// zero_velocity_threshold has n entries [rad/s or m/s] (zeros keep every row) or is empty (keeps
/// every row). Throws dynid::Error when the threshold size is neither 0 nor n.
EquationBlock differential_equations(const Model& model, const ParameterLayout& layout,
                                     bool coupling, const ProcessedRecord& processed,
                                     const Eigen::VectorXd& zero_velocity_threshold);

/// The rows of a differential block (group = joint, sample = row of `dq`) whose joint moves:
/// |dq(sample, group)| ≥ threshold[group] (the zero-velocity rule of identify() and validate).
/// dq is the processed record's samples × n velocity [rad/s or m/s]; threshold has n entries.
EquationBlock moving_rows(const EquationBlock& block, const Eigen::MatrixXd& dq,
                          const Eigen::VectorXd& threshold);

/// The stack stage: the rows of several runs' blocks one after the other. Sample indices of block
/// b start `gap` empty samples after the last of block b−1 (gap ≥ 1), so that consecutive-sample
/// statistics (lag-1 autocorrelation) never pair two runs, and a HAC window of at most gap − 1
/// lags never does either (identify() restacks with gap = window + 1 once the window is known).
/// Every block must have the same columns and group names. Throws dynid::Error for no blocks,
/// gap < 1 or mismatched columns / groups.
EquationBlock stack_equations(const std::vector<EquationBlock>& blocks, int gap = 1);

/// The base-column selection: the columns of `block` that are base parameters, in `base.base`
/// order and named base.names (W_b of Gautier–Khalil: W·θ = W_b·θ_b). The block's columns must be
/// base.layout_names. Throws dynid::Error otherwise.
EquationBlock select_base_columns(const EquationBlock& block, const BaseParameters& base);

/// What the data determine of a block's columns (issue 11 item 3; issue 25 item 1): the columns
/// scaled to unit 2-norm (so nothing depends on units), the directions the data fix to a useful
/// precision given the noise they show (DataIdentifiabilityOptions::precision), the columns a
/// left-to-right sweep keeps, and those the data leave undetermined.
struct DataIdentifiability {
  int rank = 0;  ///< data rank of the block: the columns kept (≤ columns)
  /// Singular value (column-scaled W, relative to the largest) below which a direction is not
  /// determined: max(roundoff_tolerance, noise_std / (precision · plausible_magnitude) / σ_max).
  double tolerance = 0.0;
  double noise_std = 0.0;            ///< ŝ: residual std per equation of the fit on every column
  double plausible_magnitude = 0.0;  ///< ‖y‖, the largest torque a direction can plausibly carry
  std::vector<int> kept;             ///< columns estimated, increasing
  std::vector<int> not_excited;      ///< columns the data do not determine, increasing
  /// Per kept column, the not-excited columns it absorbs on these data (name, coefficient): the
  /// kept estimate is θ_kept + Σ c·θ_not_excited (a data regrouping, like K_d for the model).
  std::vector<std::vector<std::pair<int, double>>> absorbs;
  /// Of not_excited: the columns that are combinations of the kept ones to round-off (distance to
  /// their span at most roundoff_tolerance × σ_max of the column-scaled W), e.g. the Coulomb
  /// column of a coupled motor that turns with the one joint that moves. The data regroup them
  /// exactly into the kept ones that absorb them, as the model's base set regroups columns; the
  /// other not-excited columns are the ones the noise leaves undetermined. Increasing.
  std::vector<int> regrouped;
};

/// Options of data_identifiability (Ceres style).
struct DataIdentifiabilityOptions {
  /// A direction of the column-scaled W (unit right singular vector v, singular value σ) is
  /// estimated with standard deviation ŝ/σ in the scaled parameters φ = diag(‖W_c‖)·θ, where ŝ
  /// is the residual std per equation. A unit-norm combination of columns with coefficient φ
  /// carries a torque of norm |φ| on a run that excites it fully; no combination of a physical
  /// model's parameters carries more than the robot's whole torque ‖y‖ (its plausible magnitude).
  /// The direction is determined when ŝ/σ ≤ precision·‖y‖. 1 = its standard deviation must not
  /// exceed its plausible magnitude (issue 25); below it the estimate cannot be told from 0 nor
  /// from everything measured (docs/methods/identification.md, "What the data determine").
  double precision = 1.0;
  /// Numerical floor, whatever the noise (nearly noise-free data, no residual degrees of
  /// freedom): a singular value below this × the largest is not determined. Below a column-scaled
  /// condition number of 1e8 the estimator's intervals lose their digits (the simulation of
  /// docs/methods/identification.md: 49–59 % coverage at 5e-9 and 5e-10, all at 5e-8).
  double roundoff_tolerance = 1e-8;
  /// A data-regrouping coefficient below this (relative to the column scales) is round-off.
  double absorb_threshold = 1e-6;
};

/// Rank of the data and the columns they determine (see DataIdentifiability). A column that is
/// exactly zero on the data (a joint that never moved above its noise) is never kept. Uses
/// block.y for the noise and the plausible magnitude; without it (empty, or no more rows than
/// columns) only the round-off floor applies.
DataIdentifiability data_identifiability(const EquationBlock& block,
                                         const DataIdentifiabilityOptions& options = {});

/// The block restricted to `columns` (in that order).
EquationBlock select_columns(const EquationBlock& block, const std::vector<int>& columns);

/// The block restricted to the columns named `names` (in that order): the columns an estimate
/// lives on, e.g. IdentificationResult::names (the data-identifiable base parameters, without the
/// not_excited ones) of a block over all base parameters. Throws dynid::Error naming the first
/// name that is not a column of the block.
EquationBlock select_named_columns(const EquationBlock& block,
                                   const std::vector<std::string>& names);

/// Options of estimate_block (Ceres style).
struct BlockEstimationOptions {
  IdentificationEstimator estimator = IdentificationEstimator::kOls;  ///< OLS, WLS or U-D RLS
  double confidence_level = 0.999;                                    ///< level of the intervals
  int hac_bandwidth = -1;  ///< Bartlett window in samples; −1 automatic (Andrews)
  /// With RLS: keep the estimate and its σ after every equation (BlockEstimate::history_*).
  bool record_history = false;
  /// Persistent-excitation window ρ in equations (seed 1 eq. 38); 0 = auto: max(10 × columns,
  /// rows/10).
  int excitation_window = 0;
};

/// What the estimate stage found on a block.
struct BlockEstimate {
  Estimate estimate;                      ///< values, covariance (HAC), intervals, summary
  HacSummary hac;                         ///< the covariance's window and critical value
  Eigen::VectorXd group_rms;              ///< per group, unweighted residual RMS
  Eigen::VectorXd group_relative_error;   ///< per group ‖e_g‖/‖y_g‖
  Eigen::VectorXd group_autocorrelation;  ///< per group lag-1 residual autocorrelation
  Eigen::VectorXd residual;               ///< y − W·x, unweighted, per row
  double relative_error = 0.0;            ///< ‖e‖/‖y‖
  std::string covariance_choice;          ///< one line: which covariance and why
  std::vector<std::string> warnings;      ///< estimator and residual warnings
  /// With record_history (RLS): the time of each equation, the estimate and its σ after it.
  Eigen::VectorXd history_t;
  Eigen::MatrixXd history_x, history_std;
};

/// The estimate stage: OLS, Gautier's WLS (one variance per block.group) or U-D RLS (seed 1
/// eqs. 36–37) of y = W·θ, then the Newey–West covariance over block.sample (the estimator's own
/// bread; WLS rows weighted), residual statistics per group and the lag-1 autocorrelation over
/// consecutive samples of each group (a warning names the groups above 0.5). The parameter names
/// are block.columns. Throws dynid::Error for fewer rows than columns or NaN (the estimators').
BlockEstimate estimate_block(const EquationBlock& block, const BlockEstimationOptions& options);

/// Persistent excitation (seed 1 eq. 38): α·I ≤ Σ_{i=k}^{k+ρ} d_i d_iᵀ ≤ β·I over windows of ρ
/// consecutive equations (stride ρ/2), on the regressor with each column scaled to unit mean
/// square (so α, β do not mix units); the condition holds in a window when its smallest eigenvalue
/// exceeds 1e-6 × its largest, and holds_from_t is the end time of the first window from which it
/// holds in every later window (NaN if never). ρ ≤ 0: max(10 × columns, rows/10).
ExcitationSummary persistent_excitation(const EquationBlock& block, int window);

}  // namespace dynid
