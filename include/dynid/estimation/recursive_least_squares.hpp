#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"

namespace dynid {

/// Options of recursive least squares (Ceres style).
struct RecursiveLeastSquaresOptions {
  /// c in the prior covariance P0 = c·I (seed 1, after eq. 37); the prior adds ‖x − x0‖²/c to
  /// the cost, so large c makes its effect vanish. Must be > 0.
  double initial_covariance = 1e8;
  /// Forgetting factor λ ∈ (0, 1]: a sample k steps old is weighted by λ^k (1 = no forgetting).
  double forgetting_factor = 1.0;
  /// Keep the estimate after every sample (history(), samples × p). Memory grows with samples.
  bool record_history = false;
};

/// Recursive least squares with P = U·D·Uᵀ (U unit upper triangular, D diagonal), updated by
/// Bierman's U-D measurement update (the Agee–Turner rank-one update; Bierman 1977 ch. V),
/// implementing seed 1 eqs. 36–37 with exponential forgetting:
///   K = P·d/(λ + dᵀPd),  x ← x + K·(y − dᵀx),  P ← (P − K·dᵀP)/λ.
/// Without forgetting, after samples 1..m: x = (WᵀW + I/c)⁻¹(Wᵀy + x0/c). O(p²) per sample, no
/// allocation per sample (except the optional history).
class RecursiveLeastSquares {
 public:
  /// Callback after each sample: (samples processed so far, current estimate).
  using Callback = std::function<void(Eigen::Index, const Eigen::VectorXd&)>;

  /// p ≥ 1 parameters. Throws dynid::Error if p < 1, c ≤ 0 or λ ∉ (0, 1].
  explicit RecursiveLeastSquares(Eigen::Index parameters,
                                 const RecursiveLeastSquaresOptions& options = {});

  /// Sets the prior mean x0 (default 0); only before the first sample. Throws on size mismatch.
  void set_initial_estimate(const Eigen::Ref<const Eigen::VectorXd>& x0);
  /// Called after every sample (empty function to disable).
  void set_callback(Callback callback) { callback_ = std::move(callback); }

  /// One scalar observation y = dᵀx + e (d has p entries). Throws dynid::Error on size mismatch or
  /// NaN/Inf (naming the sample index).
  void update(const Eigen::Ref<const Eigen::VectorXd>& d, double y);
  /// Every row of W (b×p) in order, as update(W.row(i), y(i)). Same errors.
  void update(const Eigen::Ref<const Eigen::MatrixXd>& W,
              const Eigen::Ref<const Eigen::VectorXd>& y);

  const Eigen::VectorXd& x() const { return x_; }                    ///< current estimate
  Eigen::MatrixXd covariance_factor() const;                         ///< U (unit upper triangular)
  const Eigen::VectorXd& covariance_diagonal() const { return d_; }  ///< D
  Eigen::MatrixXd P() const;                                         ///< U·D·Uᵀ
  Eigen::Index samples() const { return samples_; }                  ///< observations processed
  /// Minimum of the (forgetting-weighted, prior-regularised) cost
  /// J = Σ λ^{m−k}(y_k − d_kᵀx)² + λ^m (x − x0)ᵀ(x − x0)/c, via J ← λJ + λ·e²/(λ + dᵀPd).
  double cost() const { return cost_; }
  /// Estimates after every sample (samples × p); empty unless options.record_history.
  Eigen::MatrixXd history() const;

  /// Estimate with statistics: σ² = J/(m_eff − p), m_eff = Σ λ^k (= m without forgetting),
  /// covariance σ²·P, Student-t intervals; condition number of [W; I/√c] from P. No group
  /// statistics. With m_eff ≤ p the statistics are NaN and a warning is added.
  /// Throws dynid::Error if no sample was processed or options are invalid.
  Estimate estimate(const EstimationOptions& options = {}) const;

 private:
  Eigen::Index parameters_;
  RecursiveLeastSquaresOptions options_;
  Eigen::VectorXd x_;
  Eigen::MatrixXd u_;
  Eigen::VectorXd d_;
  Eigen::VectorXd f_, v_, k_, row_;  // workspace
  Eigen::Index samples_ = 0;
  double cost_ = 0.0;
  double effective_samples_ = 0.0;
  std::vector<double> history_;
  Callback callback_;
};

/// Runs RecursiveLeastSquares over all rows of W (m×p) and returns its estimate; the estimate
/// after every row goes to *history (m×p) when history is not null.
Estimate recursive_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                 const Eigen::Ref<const Eigen::VectorXd>& y,
                                 const RecursiveLeastSquaresOptions& rls_options = {},
                                 const EstimationOptions& options = {},
                                 Eigen::MatrixXd* history = nullptr);

}  // namespace dynid
