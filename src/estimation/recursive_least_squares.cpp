#include "dynid/estimation/recursive_least_squares.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/estimation/statistics.hpp"
#include "factor_solve.hpp"
#include "ud_update.hpp"

namespace dynid {

RecursiveLeastSquares::RecursiveLeastSquares(Eigen::Index parameters,
                                             const RecursiveLeastSquaresOptions& options)
    : parameters_(parameters), options_(options) {
  if (parameters < 1) {
    throw Error("RecursiveLeastSquares: parameters is " + std::to_string(parameters) +
                "; the regressor needs at least one column");
  }
  if (!(options.initial_covariance > 0.0) || !std::isfinite(options.initial_covariance)) {
    throw Error("the initial covariance (initial_covariance) is " +
                std::to_string(options.initial_covariance) + "; pass c > 0 (P0 = c*I, e.g. 1e8)");
  }
  if (!(options.forgetting_factor > 0.0 && options.forgetting_factor <= 1.0)) {
    throw Error("the forgetting factor (forgetting_factor) is " +
                std::to_string(options.forgetting_factor) +
                "; pass a value in (0, 1] (1 = no forgetting)");
  }
  x_ = Eigen::VectorXd::Zero(parameters);
  u_ = Eigen::MatrixXd::Identity(parameters, parameters);
  d_ = Eigen::VectorXd::Constant(parameters, options.initial_covariance);
  f_.resize(parameters);
  v_.resize(parameters);
  k_.resize(parameters);
  row_.resize(parameters);
}

void RecursiveLeastSquares::set_initial_estimate(const Eigen::Ref<const Eigen::VectorXd>& x0) {
  if (samples_ > 0) {
    throw Error("RecursiveLeastSquares: the initial estimate was set after " +
                std::to_string(samples_) + " samples; set it before the first update");
  }
  if (x0.size() != parameters_ || !x0.allFinite()) {
    throw Error("initial estimate has " + std::to_string(x0.size()) +
                " entries or non-finite values; pass " + std::to_string(parameters_) +
                " finite values");
  }
  x_ = x0;
}

void RecursiveLeastSquares::update(const Eigen::Ref<const Eigen::VectorXd>& d, double y) {
  const Eigen::Index p = parameters_;
  if (d.size() != p) {
    throw Error("regressor row of sample " + std::to_string(samples_) + " has " +
                std::to_string(d.size()) + " entries; pass " + std::to_string(p) +
                " (one per parameter)");
  }
  if (!d.allFinite() || !std::isfinite(y)) {
    throw Error("sample " + std::to_string(samples_) +
                " contains NaN or Inf in W or y; remove or repair that sample");
  }
  const double lambda = options_.forgetting_factor;
  // Bierman's U-D update with measurement variance λ: afterwards UDUᵀ = P − P d dᵀP/(λ + dᵀPd).
  const double alpha = estimation_detail::ud_update(u_, d_, d, lambda, f_, v_, k_);
  // Seed 1 eq. 36: x ← x + K·(y − dᵀx), K = P d/(λ + dᵀPd) = k/α.
  const double innovation = y - d.dot(x_);
  x_ += (innovation / alpha) * k_;
  // Forgetting: P ← P/λ.
  if (lambda != 1.0) d_ /= lambda;
  cost_ = lambda * cost_ + lambda * innovation * innovation / alpha;
  effective_samples_ = lambda * effective_samples_ + 1.0;
  ++samples_;
  if (options_.record_history) history_.insert(history_.end(), x_.data(), x_.data() + p);
  if (callback_) callback_(samples_, x_);
}

void RecursiveLeastSquares::update(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                   const Eigen::Ref<const Eigen::VectorXd>& y) {
  estimation_detail::check_sizes(W, y, parameters_);
  if (options_.record_history) history_.reserve(history_.size() + W.rows() * parameters_);
  // A row of a column-major W is strided; copy it into the workspace (no allocation per sample).
  for (Eigen::Index i = 0; i < W.rows(); ++i) {
    row_ = W.row(i).transpose();
    update(row_, y(i));
  }
}

Eigen::MatrixXd RecursiveLeastSquares::covariance_factor() const {
  return u_;
}

Eigen::MatrixXd RecursiveLeastSquares::P() const {
  return u_ * d_.asDiagonal() * u_.transpose();
}

Eigen::MatrixXd RecursiveLeastSquares::history() const {
  const Eigen::Index n = static_cast<Eigen::Index>(history_.size()) / parameters_;
  return Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      history_.data(), n, parameters_);
}

Estimate RecursiveLeastSquares::estimate(const EstimationOptions& options) const {
  const Eigen::Index p = parameters_;
  estimation_detail::check_names(options, p);
  if (samples_ == 0) {
    throw Error("RecursiveLeastSquares has no samples; call update() with data first");
  }
  Estimate e;
  e.x = x_;
  e.summary.estimator = EstimatorKind::kRecursiveLeastSquares;
  e.summary.rows = samples_;
  e.summary.columns = p;
  e.summary.rank = p;  // P is positive definite thanks to the prior
  e.summary.passes = 1;
  const Eigen::MatrixXd P = this->P();
  // P⁻¹ = WᵀΛW + λ^m I/c, so cond([W; I/√c]) = sqrt(cond(P)).
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(P, Eigen::EigenvaluesOnly);
  const double lmin = eig.eigenvalues()(0), lmax = eig.eigenvalues()(p - 1);
  e.summary.condition_number =
      lmin > 0.0 ? std::sqrt(lmax / lmin) : std::numeric_limits<double>::infinity();
  const double dof = effective_samples_ - double(p);
  e.degrees_of_freedom = static_cast<Eigen::Index>(std::floor(effective_samples_ + 1e-9)) - p;
  e.residual_variance = dof > 0.0 ? cost_ / dof : std::numeric_limits<double>::quiet_NaN();
  e.covariance = e.residual_variance * P;
  fill_parameter_statistics(e, options);
  if (e.summary.condition_number > options.condition_warning) {
    e.summary.warnings.push_back("condition number " + short_number(e.summary.condition_number) +
                                 " exceeds " + short_number(options.condition_warning) +
                                 ": the data excite some parameters poorly");
  }
  if (!e.poorly_excited.empty()) {
    e.summary.warnings.push_back("poorly excited parameters: " +
                                 estimation_detail::column_list(options, e.poorly_excited));
  }
  return e;
}

Estimate recursive_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                 const Eigen::Ref<const Eigen::VectorXd>& y,
                                 const RecursiveLeastSquaresOptions& rls_options,
                                 const EstimationOptions& options, Eigen::MatrixXd* history) {
  if (W.cols() == 0) {
    throw Error("W has no columns; pass a regressor with at least one parameter column");
  }
  RecursiveLeastSquaresOptions o = rls_options;
  if (history != nullptr) o.record_history = true;
  RecursiveLeastSquares rls(W.cols(), o);
  rls.update(W, y);
  Estimate e = rls.estimate(options);
  if (history != nullptr) *history = rls.history();
  return e;
}

}  // namespace dynid
