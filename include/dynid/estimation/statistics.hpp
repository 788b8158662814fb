#pragma once

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"

namespace dynid {

/// Two-sided Student-t quantile: returns t with P(|T| ≤ t) = level for T ~ t(dof).
/// Used for the confidence intervals x ± t·σ_x of seed 2 Table 3. Boost.Math.
/// Throws dynid::Error if level ∉ (0, 1) or dof ≤ 0.
double student_t_quantile(double level, double dof);

/// Fills the parameter statistics of `estimate` from its x, covariance and degrees_of_freedom:
/// std_dev = sqrt(diag C), relative_std_percent = 100·σ_x/|x|, Student-t intervals at
/// options.confidence_level with degrees_of_freedom, and the poorly excited list (relative σ
/// above options.poorly_excited_percent). Columns listed in estimate.unidentifiable get infinite σ.
/// When degrees_of_freedom ≤ 0 the statistics are NaN and a warning is added.
/// Throws dynid::Error if options.confidence_level ∉ (0, 1).
void fill_parameter_statistics(Estimate& estimate, const EstimationOptions& options);

/// Options of apply_hac_covariance (Ceres style).
struct HacOptions {
  /// Bartlett lag window: lags 0…bandwidth of the per-sample scores are summed. −1 = automatic,
  /// Andrews' (1991) AR(1) plug-in rule on the scores, capped at (samples − 1)/4.
  int bandwidth = -1;
  /// Andrews–Monahan (1992) VAR(1) pre-whitening of the scores before the Bartlett window, then
  /// recolouring: removes most of the kernel's downward bias under strong autocorrelation.
  bool prewhiten = true;
  /// Smallest automatic window as a fraction b = (bandwidth + 1)/samples: the Andrews rule targets
  /// the variance's mean-squared error, not coverage, and picks a few lags on pre-whitened scores;
  /// 0.02 is the smallest round fraction that reached the level under white, AR(1) and
  /// unmodelled-term residuals (docs/methods/estimation.md §5). Ignored for a given bandwidth.
  double min_bandwidth_fraction = 0.02;
  /// Half-widths from the fixed-b critical value of the Bartlett HAC t-statistic
  /// (fixed_b_critical_value) instead of the Student-t quantile: the HAC variance is itself noisy.
  bool fixed_b = true;
};

/// What apply_hac_covariance found.
struct HacSummary {
  int bandwidth = 0;            ///< Bartlett lags used
  double score_lag1 = 0.0;      ///< weighted mean lag-1 autocorrelation of the per-sample scores
  double median_ratio = 1.0;    ///< median over parameters of std_dev / std_dev_white
  double b = 0.0;               ///< (bandwidth + 1)/samples, the fixed-b fraction
  double critical_value = 0.0;  ///< half-width multiplier of the HAC intervals
};

/// Two-sided fixed-b critical value c of the Bartlett-kernel HAC t-statistic: P(|t| ≤ c) = level
/// under the Kiefer–Vogelsang limit t = Z/√Q(b), Z ~ N(0,1) independent of Q(b), the Bartlett
/// long-run-variance functional of a Brownian bridge with window b (fraction of the sample).
/// Q is drawn by a fixed-seed simulation (1000 steps, 2000 draws, exact partial-sum form of the
/// Bartlett sum) and c solved from mean(erf(c·√Q/√2)) = level, which holds for any level.
/// c → the normal quantile as b → 0. Kiefer & Vogelsang (2005), Econometric Theory 21 (their
/// cubic cv(b) tables are the test oracle); derivation in docs/methods/estimation.md §5.
/// Throws dynid::Error if level ∉ (0, 1) or b ∉ [0, 1].
double fixed_b_critical_value(double level, double b);

/// Bartlett (Newey–West) long-run covariance of a score series: S = Σ_|l|≤L (1 − |l|/(L+1))·Γ_l,
/// Γ_l = Σ_k g_k g_{k−l}ᵀ, for `scores` (T×p, row k = g_kᵀ) and `lags` = L ≥ 0 (capped at T − 1).
/// Identity used: with M = L + 1, (M − |t−s|)₊ counts the windows of M consecutive samples that
/// hold both t and s, so S = (1/M)·Σ_j B_j B_jᵀ with B_j the sum of the scores in window j, formed
/// from running sums in O(T·p²) whatever L (the lag-by-lag sum costs O(L·T·p²)). Newey & West
/// (1987); derivation in docs/methods/estimation.md §5. Throws dynid::Error if lags < 0.
Eigen::MatrixXd bartlett_long_run_covariance(const Eigen::Ref<const Eigen::MatrixXd>& scores,
                                             int lags);

/// Replaces the white-noise covariance of `estimate` by the Newey–West (HAC) sandwich
/// C = m/(m−r) · B·S·B with bread B = (WᵀW)⁻¹ = covariance/σ² (the estimator's own, so the
/// weighting of WLS and the prior of RLS carry over), and meat S = Σ_|l|≤L (1 − |l|/(L+1))·Γ_l,
/// Γ_l = Σ_k g_k g_{k−l}ᵀ, where the score g_k = Σ_{i: sample(i)=k} W_iᵀ·e_i sums the n joint rows
/// of sample k (their residuals are correlated across joints too). With options.prewhiten the
/// window runs on v_k = g_k − A·g_{k−1} (A the least-squares VAR(1) of the scores, singular
/// values capped at 0.97) and S = (I − A)⁻¹ S_v (I − A)⁻ᵀ. Keeps the white statistics in
/// std_dev_white / ci_*_white (Student-t quantile) and refills std_dev, the intervals (half-width
/// critical_value·std_dev, the fixed-b value with options.fixed_b) and the poorly-excited list. W
/// (m×p) and e (m) must be the rows the estimator solved (weighted for WLS); sample (m entries, ≥
/// 0, non-decreasing) gives the time index of each row, gaps allowed. Newey & West (1987), Andrews
/// (1991); derivation in docs/methods/estimation.md. Throws dynid::Error for size mismatches or a
/// decreasing sample index.
HacSummary apply_hac_covariance(Estimate& estimate, const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& e,
                                const Eigen::Ref<const Eigen::VectorXi>& sample,
                                const EstimationOptions& estimation_options,
                                const HacOptions& options = {});

}  // namespace dynid
