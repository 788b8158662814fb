#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// Which estimator produced an Estimate.
enum class EstimatorKind {
  kOrdinaryLeastSquares,   ///< QR least squares, one pass
  kWeightedLeastSquares,   ///< Gautier's two-step weighted least squares (per-group variances)
  kRecursiveLeastSquares,  ///< U-D-Uᵀ recursive least squares (seed 1 eqs. 36–37)
  kMaximumLikelihood       ///< errors in variables (seed 2 eqs. 13–16)
};

/// Lower-case name of an estimator kind ("ordinary_least_squares", ...), for reports and JSON.
const char* to_string(EstimatorKind kind);

/// Options shared by every estimator of the linear model y = W·x + e (Ceres style).
struct EstimationOptions {
  /// Two-sided confidence level of the Student-t intervals, in (0, 1). 0.999 as in seed 2 Table 3.
  double confidence_level = 0.999;
  /// Singular values of W not above rank_tolerance·σ_max count as zero. 0 selects the automatic
  /// tolerance max(m, p)·ε (as numpy/MATLAB rank), ε = machine epsilon.
  double rank_tolerance = 0.0;
  /// A parameter whose relative standard deviation 100·σ_x/|x| exceeds this (percent) is listed as
  /// poorly excited (Gautier's rule of thumb for badly identified parameters).
  double poorly_excited_percent = 30.0;
  /// When cond(W) exceeds this, parameters dominating the weakest singular direction are also
  /// listed as poorly excited.
  double condition_warning = 1e4;
  /// A parameter dominates the weakest direction when |v_min,j| is at least this (v_min is the
  /// unit right singular vector of the smallest singular value).
  double weak_direction_threshold = 0.5;
  /// Column (parameter) names used in warnings; empty selects "x<j>". Size 0 or p.
  std::vector<std::string> names;
  /// What the user can do about columns the data do not determine, in the caller's terms (a
  /// command's flags, a better run), ending the rank-deficiency warning; empty: regroup them into
  /// base parameters or drop the dependent columns (the estimator's own view).
  std::string rank_deficient_remedy;
};

/// What an estimator did (Ceres style): sizes, numerical outcome and warnings.
struct Summary {
  EstimatorKind estimator = EstimatorKind::kOrdinaryLeastSquares;  ///< which estimator ran
  Eigen::Index rows = 0;                                           ///< observations m (rows of W)
  Eigen::Index columns = 0;                                        ///< parameters p (columns of W)
  Eigen::Index rank = 0;        ///< numerical rank of W (of the weighted W for WLS)
  double rank_tolerance = 0.0;  ///< absolute singular-value threshold that decided the rank
  /// σ_max/σ_min of W (weighted W for WLS; of [W; I/√c] for RLS); +inf when singular.
  double condition_number = 0.0;
  int passes = 0;  ///< least-squares solves (OLS 1, WLS 2, RLS 1 sweep over the data)
  std::vector<std::string> warnings;  ///< numerical outcomes the user should know about

  /// One-paragraph human-readable report.
  std::string brief_report() const;
};

/// Result of an estimator of y = W·x + e: the estimate, its uncertainty, residual statistics
/// (Gautier) and a Summary. Group vectors are indexed by row group (joint), NaN for a group
/// without rows; empty for RLS.
struct Estimate {
  Eigen::VectorXd x;           ///< estimate (p); minimum-norm solution if W is rank deficient
  Eigen::MatrixXd covariance;  ///< σ²·(WᵀW)⁻¹ (pseudo-inverse if rank deficient), p×p
  Eigen::VectorXd std_dev;     ///< sqrt(diag(covariance)); +inf for unidentifiable columns
  Eigen::VectorXd relative_std_percent;  ///< 100·σ_x/|x| (+inf when x = 0)
  double confidence_level = 0.0;         ///< level of the intervals below
  double t_quantile = 0.0;               ///< Student-t quantile t with P(|T| ≤ t) = level
  /// Half-width multiplier c of ci_lower/ci_upper: t_quantile for the white covariance, the
  /// fixed-b critical value for a HAC one (fixed_b_critical_value).
  double critical_value = 0.0;
  Eigen::VectorXd ci_lower;  ///< x − c·σ_x
  Eigen::VectorXd ci_upper;  ///< x + c·σ_x
  /// σ_x of the white-noise covariance σ²·(WᵀW)⁻¹ when `covariance` was replaced by a sandwich
  /// (apply_hac_covariance); else empty. Too narrow when the residuals are correlated.
  Eigen::VectorXd std_dev_white;
  Eigen::VectorXd ci_lower_white;  ///< x − t·std_dev_white (empty like std_dev_white)
  Eigen::VectorXd ci_upper_white;  ///< x + t·std_dev_white (empty like std_dev_white)
  /// Which covariance `covariance`, std_dev and the intervals come from ("white" or a HAC rule).
  std::string covariance_kind = "white";
  double residual_variance = 0.0;  ///< σ² = ‖e‖²/(m − rank) (weighted residual for WLS)
  Eigen::Index degrees_of_freedom = 0;   ///< m − rank
  double residual_rms = 0.0;             ///< sqrt(‖e‖²/m), unweighted
  double relative_error = 0.0;           ///< ‖e‖/‖y‖, unweighted
  Eigen::VectorXd group_rows;            ///< rows per group
  Eigen::VectorXd group_rms;             ///< sqrt(‖e_g‖²/m_g), unweighted
  Eigen::VectorXd group_relative_error;  ///< ‖e_g‖/‖y_g‖
  /// Per-group noise variance σ_g² = ‖y_g − W_g x_g‖²/(m_g − rank W_g), x_g the least-squares
  /// solution of group g's rows alone (Gautier); the WLS weights are 1/σ_g. NaN without dof.
  Eigen::VectorXd group_variance;
  Eigen::VectorXd singular_values;              ///< of W (weighted W for WLS), descending
  std::vector<Eigen::Index> unidentifiable;     ///< columns with a component in W's null space
  std::vector<Eigen::Index> dependent_columns;  ///< columns to drop for a full-rank set (pivoting)
  std::vector<Eigen::Index> poorly_excited;     ///< see EstimationOptions
  Summary summary;                              ///< what happened
};

}  // namespace dynid
