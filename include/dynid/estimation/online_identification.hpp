#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// Options of OnlineIdentification (Ceres style).
struct OnlineIdentificationOptions {
  /// Forgetting factor λ ∈ (0, 1] per sample (all n joint rows of a sample share one weight): a
  /// sample k samples old weighs λ^k, so 1/(1 − λ) samples is the memory (1 = no forgetting).
  double forgetting_factor = 0.999;
  /// c in the prior covariance P0 = c·I of the base parameters; must be > 0.
  double initial_covariance = 1e4;
  /// Largest diagonal entry of D (the U-D factor of P) [parameter units²]; when forgetting inflates
  /// an unexcited direction beyond it, that direction stops being forgotten (covariance wind-up
  /// protection). Must be ≥ initial_covariance; +inf disables it.
  double max_covariance = 1e8;
};

/// Outcome of one OnlineIdentification::update.
enum class OnlineStatus {
  kUpdated,    ///< the estimate now includes the sample
  kWrongSize,  ///< an argument did not have n entries; nothing changed
  kNonFinite,  ///< an argument held NaN or Inf; nothing changed
};

/// Real-time on-line identification of the base parameters (the recursive least squares of seed 1
/// eqs. 36–37, which seed 1 ran off-line, here per control sample): each update() takes one sample
/// (q, dq, ddq, tau) — measured or filtered — builds the torque regressor of the layout, keeps its
/// base columns (W_b = W_1, BaseParameters::select) and folds the n joint rows into the U-D
/// factors of P by Bierman's update, after P ← P/λ once per sample. Equals the batch solution
/// x = (Σ_k λ^{m−k} W_kᵀW_k + λ^m I/c)⁻¹(Σ_k λ^{m−k} W_kᵀτ_k + λ^m x0/c) while no D entry reaches
/// max_covariance. Real-time safe: the constructor allocates everything; update() allocates
/// nothing, takes no lock, throws nothing and costs O(n·p² + n·columns) for p base parameters.
/// Units: SI (joint side); the base parameters' units are those of their leading standard ones.
/// One object per thread.
class OnlineIdentification {
 public:
  /// The model gives the kinematics and gravity (its inertial values are not used); `base` must
  /// come from compute_base_parameters for this model and `layout`. Throws dynid::Error on
  /// invalid options or when base and layout disagree in their column count.
  OnlineIdentification(const Model& model, const ParameterLayout& layout,
                       const BaseParameters& base, const OnlineIdentificationOptions& options = {});

  /// Sets the prior mean x0 of the base parameters (e.g. base.reduce(nominal θ)); before the first
  /// update. Throws dynid::Error on a wrong size, non-finite values, or after an update.
  void set_initial_estimate(const Eigen::Ref<const Eigen::VectorXd>& x0);

  /// One sample: joint positions, velocities, accelerations [rad, rad/s, rad/s² or m, m/s, m/s²]
  /// and joint torques [N·m or N], size n each. Real-time safe (see the class comment).
  OnlineStatus update(const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& ddq,
                      const Eigen::Ref<const Eigen::VectorXd>& tau);

  /// Current base-parameter estimate (size p, in base.names order).
  const Eigen::VectorXd& estimate() const { return x_; }
  /// Torques the estimate predicted for the last sample before it was folded in (a priori, size
  /// n): tau − predicted is the innovation, the on-line measure of model error.
  const Eigen::VectorXd& predicted_torque() const { return predicted_; }
  /// Diagonal of P = U·D·Uᵀ (size p): each parameter's variance per unit torque-noise variance.
  Eigen::VectorXd covariance_diagonal() const;
  /// Samples folded in so far.
  long samples() const { return samples_; }
  /// Number of base parameters p.
  Eigen::Index parameters() const { return x_.size(); }

 private:
  Model model_;
  ParameterLayout layout_;
  std::vector<int> base_columns_;
  OnlineIdentificationOptions options_;
  Workspace ws_;
  Eigen::MatrixXd y_full_;  // n × layout columns
  Eigen::MatrixXd u_;       // U of P = U D Uᵀ
  Eigen::VectorXd d_, x_, f_, v_, k_, row_, predicted_;
  long samples_ = 0;
};

}  // namespace dynid
