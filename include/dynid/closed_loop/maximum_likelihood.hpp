#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/common/progress.hpp"

#include "dynid/closed_loop/projection.hpp"
#include "dynid/estimation/equation_block.hpp"
#include "dynid/estimation/estimate.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/pipeline.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// Standard deviations of the measured variables of a differential block, per joint (seed 2
/// eq. 16's σ²). q, dq, ddq [rad, rad/s, rad/s² or m, m/s, m/s²]: the noise on the signals the
/// regressor is built from (after filtering and differentiation); an empty vector is noise-free.
/// tau [N·m or N]: required, every entry > 0.
struct MeasurementNoise {
  Eigen::VectorXd q, dq, ddq, tau;
};

/// Options of maximum_likelihood() (Ceres style).
struct MaximumLikelihoodOptions {
  int max_iterations = 100;            ///< Levenberg–Marquardt iterations (Ceres)
  double function_tolerance = 1e-12;   ///< relative cost change that ends the iterations
  double parameter_tolerance = 1e-12;  ///< relative step that ends the iterations
  /// Intervals from a Newey–West sandwich over samples on the whitened scores (as identify()'s
  /// default), the information-based ones kept as std_dev_white; false: information only.
  bool hac = true;
  /// > 0: the rows are projected signals (closed loop) spanning this many dimensions in all
  /// (Σ over runs and joints of the projector's rank); the intervals then come from
  /// projected_statistics() on the whitened rows with that many degrees of freedom less the
  /// parameters (no HAC: projected residuals are smooth by construction).
  Eigen::Index projected_dimensions = 0;
  /// Called after each Levenberg–Marquardt iteration with iteration / max_iterations (the solve
  /// usually ends earlier) and the cost (common/progress.hpp); may be empty.
  ProgressCallback progress;
};

/// What the maximum-likelihood solve did (Ceres style).
struct MaximumLikelihoodSummary {
  int iterations = 0;         ///< Levenberg–Marquardt iterations
  double initial_cost = 0.0;  ///< eq. 15 at the start
  double final_cost = 0.0;    ///< eq. 15 at the estimate
  bool converged = false;     ///< Ceres reported convergence
  std::string termination;    ///< Ceres' message
  /// 2·final_cost / (samples' rows − parameters): ≈ 1 when the noise standard deviations are
  /// right; above 1, the noise was underestimated (or the model lacks a term).
  double variance_factor = 0.0;
};

/// ∂W_i/∂(q, q̇, q̈) of every row i of a differential block, columns `columns` of the sample-major
/// regressor of `processed` (processed_regressor()): rows 3n·i … 3n·i + 3n − 1 of the result are
/// the derivatives of row i with respect to q_1…q_n, q̇_1…q̇_n, q̈_1…q̈_n of its sample, so that
/// ∂(W_i·θ)/∂x = (that block)·θ (seed 2 eq. 16's B without the torque column). Row i is sample
/// `sample[i]`, joint `joint[i]` of the record (a differential block's sample and group). By
/// central differences of the regressor: exact for q̇ (W is quadratic in it) and q̈ (linear),
/// O(h²) for q. Coulomb columns have no derivative (taken as given). Size (3n·rows) × columns.
/// Throws dynid::Error for an index outside the record.
Eigen::MatrixXd differential_sensitivity(const Model& model, const ParameterLayout& layout,
                                         bool coupling, const ProcessedRecord& processed,
                                         const std::vector<int>& columns,
                                         const Eigen::VectorXi& sample,
                                         const Eigen::VectorXi& joint);

/// Maximum-likelihood estimate with errors in variables (seed 2 eqs. 13–16; Olsen 2003): minimises
/// ½ Σ_k b_kᵀ S_k⁻¹ b_k over θ, b_k = τ_k − W_k·θ the rows of sample k, S_k = B_k σ² B_kᵀ with
/// B_k = [∂(W_k θ)/∂(q, q̇, q̈), I] (eq. 16: the torque noise plus the noise of the variables the
/// regressor is built from, propagated through the model). Solved by Levenberg–Marquardt (Ceres)
/// from `start` (the OLS estimate). Covariance: σ_f²·F⁻¹, F = Σ_k W_kᵀ S_k⁻¹ W_k the information at
/// the estimate and σ_f² the variance factor (≈ 1 when the noise is right), then by default a HAC
/// sandwich over samples on the whitened rows (std_dev_white keeps σ_f²·F⁻¹). `block`: a
/// differential block over the estimated columns (group = joint, sample = sample);
/// `sensitivity`: differential_sensitivity() of the same rows and columns. Throws dynid::Error for
/// sizes that do not match, a non-positive or non-finite torque noise, or a start that is not
/// finite.
Estimate maximum_likelihood(const EquationBlock& block, const Eigen::MatrixXd& sensitivity,
                            const MeasurementNoise& noise, const Eigen::VectorXd& start,
                            const EstimationOptions& estimation_options = {},
                            const MaximumLikelihoodOptions& options = {},
                            MaximumLikelihoodSummary* summary = nullptr);

/// Eq. 15's whitened residuals at θ (seed 2 eqs. 15–16), in the block's row order: per sample k,
/// L_k⁻¹·b_k with b_k = τ_k − W_k·θ and S_k = L_k·L_kᵀ = B_k σ² B_kᵀ, so that eq. 15's cost is
/// ½‖result‖². With `jacobian`, also their exact derivative with respect to θ (rows × p; J is
/// linear in θ, docs/methods/closed_loop.md "Jacobian"), the one maximum_likelihood()
/// hands to Ceres. Arguments as maximum_likelihood() (θ for `start`). Throws dynid::Error as
/// maximum_likelihood(), and when some S_k is not positive definite.
Eigen::VectorXd maximum_likelihood_residual(const EquationBlock& block,
                                            const Eigen::MatrixXd& sensitivity,
                                            const MeasurementNoise& noise,
                                            const Eigen::VectorXd& theta,
                                            Eigen::MatrixXd* jacobian = nullptr);

/// Noise of the processed signals (MeasurementNoise) from raw sensor noise: σ_q·g₀, σ_q·g₁,
/// σ_q·g₂ and σ_τ·g₀, g_k = white_noise_gain() of identify()'s zero-phase filter (as preprocess()
/// designs it from `signal` and the run's cut-off, unit DC gain) followed by k central
/// differences at the raw rate. Raw σ from `given` where set, else estimated from `raw` (the
/// run as logged): σ_q = processed.position_noise_std, σ_τ = the white floor of τ's spectrum
/// (position_noise_floor applied to τ). `how` receives one line saying which. Throws
/// dynid::Error when σ_τ is not > 0 (given as 0, or no floor visible: give it).
MeasurementNoise processed_noise(const SensorNoise& given, const SignalOptions& signal,
                                 const ProcessedRecord& processed, const JointRecord& raw,
                                 std::string& how);

/// Noise of closed-loop projected signals (prepare_closed_loop()) for maximum_likelihood(). A white
/// noise of std σ through the orthogonal rank-d projector P of N samples has per-sample variance
/// σ²·P_tt, σ²·d/N on average; q̂' and q̂'' are the derivatives of the projected q, so their noise
/// has on average σ²·‖DᵏU‖²_F/N, U an orthonormal basis of P's range (from P applied to a
/// fixed-seed Gaussian matrix) and D central differences at `ts` [s] (exact to (hω·ts)²/6 on a
/// band far below Nyquist). Raw σ from `given` where set, else the remainders as white noise:
/// σ_q = processed.position_noise_std (q − q̂), σ_τ = torque_remainder_std (τ − τ̂).
/// docs/methods/closed_loop.md "After a projection". `how` receives one line. Throws
/// dynid::Error when σ_τ is not > 0 or the sizes do not match.
MeasurementNoise projected_noise(const SensorNoise& given, const SignalProjector& projector,
                                 double ts, const ProcessedRecord& processed,
                                 const Eigen::VectorXd& torque_remainder_std, std::string& how);

/// The closed-loop preparation maximum_likelihood_stage() needs; no projector: a direct run.
struct ProjectedRun {
  std::shared_ptr<const SignalProjector> projector;  ///< the first run's projection
  Eigen::VectorXd torque_remainder_std;              ///< its τ − τ̂ std per joint [N·m or N]
  Eigen::Index dimensions = 0;  ///< Σ over runs and joints of the projector's rank
};

/// The estimate stage of identify() with IdentificationEstimator::kMl: maximum_likelihood() on
/// the stacked equations `stacked` (data-identifiable base columns `columns` of the layout) from
/// fit's OLS estimate, with the sensitivity of every run's block (`blocks`, `processed` in run
/// order) and processed_noise() of the first run (after a closed-loop projection, `projected`:
/// projected_noise() and projected intervals); fit's estimate, residuals and covariance choice
/// are replaced and the noise used is appended to `choices`. Throws as maximum_likelihood().
void maximum_likelihood_stage(const Model& model, const IdentifyOptions& options, bool coupling,
                              const std::vector<EquationBlock>& blocks,
                              const std::vector<ProcessedRecord>& processed,
                              const JointRecord& first_raw, const std::vector<int>& columns,
                              const EquationBlock& stacked, const ProjectedRun& projected,
                              BlockEstimate& fit,
                              std::vector<std::pair<std::string, std::string>>& choices);

}  // namespace dynid
