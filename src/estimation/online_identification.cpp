#include "dynid/estimation/online_identification.hpp"

#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "ud_update.hpp"

namespace dynid {

OnlineIdentification::OnlineIdentification(const Model& model, const ParameterLayout& layout,
                                           const BaseParameters& base,
                                           const OnlineIdentificationOptions& options)
    : model_(model),
      layout_(layout),
      base_columns_(base.base),
      options_(options),
      ws_(model_),
      y_full_(model.dof(), layout.columns(model.dof())) {
  const double lambda = options.forgetting_factor;
  if (!(lambda > 0.0 && lambda <= 1.0)) {
    throw Error("the forgetting factor (forgetting_factor) is " + std::to_string(lambda) +
                "; pass a value in (0, 1], e.g. 0.999 (1 = no forgetting)");
  }
  if (!(options.initial_covariance > 0.0) || !std::isfinite(options.initial_covariance)) {
    throw Error("the initial covariance (initial_covariance) is " +
                std::to_string(options.initial_covariance) + "; pass c > 0 (P0 = c*I, e.g. 1e4)");
  }
  if (!(options.max_covariance >= options.initial_covariance)) {
    throw Error("the max covariance (max_covariance) is " + std::to_string(options.max_covariance) +
                "; pass a value >= initial_covariance (or +inf to disable the limit)");
  }
  const int columns = layout.columns(model.dof());
  if (static_cast<int>(base.layout_names.size()) != columns || base.base.empty()) {
    throw Error("OnlineIdentification: the base parameters classify " +
                std::to_string(base.layout_names.size()) + " columns but the layout has " +
                std::to_string(columns) +
                "; compute them with compute_base_parameters for this model and layout");
  }
  for (int c : base.base) {
    if (c < 0 || c >= columns) {
      throw Error("OnlineIdentification: base column " + std::to_string(c) +
                  " is outside the layout's " + std::to_string(columns) +
                  " columns; compute the base parameters for this layout");
    }
  }
  const Eigen::Index p = static_cast<Eigen::Index>(base_columns_.size());
  u_ = Eigen::MatrixXd::Identity(p, p);
  d_ = Eigen::VectorXd::Constant(p, options.initial_covariance);
  x_ = Eigen::VectorXd::Zero(p);
  f_.resize(p);
  v_.resize(p);
  k_.resize(p);
  row_.resize(p);
  predicted_ = Eigen::VectorXd::Zero(model.dof());
}

void OnlineIdentification::set_initial_estimate(const Eigen::Ref<const Eigen::VectorXd>& x0) {
  if (samples_ > 0) {
    throw Error("OnlineIdentification: the initial estimate was set after " +
                std::to_string(samples_) + " samples; set it before the first update");
  }
  if (x0.size() != x_.size() || !x0.allFinite()) {
    throw Error("initial estimate has " + std::to_string(x0.size()) +
                " entries or non-finite values; pass " + std::to_string(x_.size()) +
                " finite values (one per base parameter)");
  }
  x_ = x0;
}

OnlineStatus OnlineIdentification::update(const Eigen::Ref<const Eigen::VectorXd>& q,
                                          const Eigen::Ref<const Eigen::VectorXd>& dq,
                                          const Eigen::Ref<const Eigen::VectorXd>& ddq,
                                          const Eigen::Ref<const Eigen::VectorXd>& tau) {
  const int n = model_.dof();
  if (q.size() != n || dq.size() != n || ddq.size() != n || tau.size() != n) {
    return OnlineStatus::kWrongSize;
  }
  if (!q.allFinite() || !dq.allFinite() || !ddq.allFinite() || !tau.allFinite()) {
    return OnlineStatus::kNonFinite;
  }
  torque_regressor(model_, ws_, layout_, q, dq, ddq, y_full_);
  // P ← P/λ once per sample (Var(e) = 1 for every row afterwards), bounded by max_covariance so
  // that directions the trajectory does not excite do not grow without limit.
  const double lambda = options_.forgetting_factor;
  if (lambda != 1.0) {
    d_ = (d_ / lambda).cwiseMin(options_.max_covariance);
  }
  const Eigen::Index p = x_.size();
  for (int i = 0; i < n; ++i) {
    for (Eigen::Index c = 0; c < p; ++c) row_(c) = y_full_(i, base_columns_[c]);
    predicted_(i) = row_.dot(x_);  // the a priori prediction, before this sample's rows enter
  }
  for (int i = 0; i < n; ++i) {
    for (Eigen::Index c = 0; c < p; ++c) row_(c) = y_full_(i, base_columns_[c]);
    const double alpha = estimation_detail::ud_update(u_, d_, row_, 1.0, f_, v_, k_);
    // Seed 1 eq. 36: x ← x + K·(τ_i − dᵀx), K = P d/(1 + dᵀPd) = k/α.
    x_ += ((tau(i) - row_.dot(x_)) / alpha) * k_;
  }
  ++samples_;
  return OnlineStatus::kUpdated;
}

Eigen::VectorXd OnlineIdentification::covariance_diagonal() const {
  return (u_ * d_.asDiagonal() * u_.transpose()).diagonal();
}

}  // namespace dynid
