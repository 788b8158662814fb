#include "dynid/estimation/streaming_least_squares.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/estimation/statistics.hpp"
#include "factor_solve.hpp"

namespace dynid {

using estimation_detail::check_names;
using estimation_detail::column_list;
using estimation_detail::solve_factor;
using estimation_detail::triangular_append;

namespace {
// Rows gathered per group before a Householder update; bounds the scratch memory.
constexpr Eigen::Index kChunk = 256;
// Group variances below this fraction of the largest are floored (WLS weights stay finite).
constexpr double kVarianceFloor = 1e-12;
}  // namespace

StreamingLeastSquares::StreamingLeastSquares(Eigen::Index parameters, int groups)
    : parameters_(parameters) {
  if (parameters < 1) {
    throw Error("StreamingLeastSquares: parameters is " + std::to_string(parameters) +
                "; W needs at least one column");
  }
  if (groups < 1) {
    throw Error("StreamingLeastSquares: groups is " + std::to_string(groups) +
                "; pass at least one row group (e.g. the joint count)");
  }
  const Eigen::Index q = parameters + 1;
  factors_.assign(groups, Eigen::MatrixXd::Zero(q, q));
  group_rows_.assign(groups, 0);
  scratch_.resize(kChunk, q);
  work_.resize(q);
  chunk_rows_.resize(groups);
  for (auto& r : chunk_rows_) r.reserve(kChunk);
}

void StreamingLeastSquares::reset() {
  for (auto& f : factors_) f.setZero();
  std::fill(group_rows_.begin(), group_rows_.end(), 0);
  rows_ = 0;
}

void StreamingLeastSquares::check_block(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                        const Eigen::Ref<const Eigen::VectorXd>& y) const {
  if (W.cols() != parameters_) {
    throw Error("W has " + std::to_string(W.cols()) + " columns but the estimator has " +
                std::to_string(parameters_) + " parameters; pass one column per parameter");
  }
  if (y.size() != W.rows()) {
    throw Error("y has " + std::to_string(y.size()) + " rows but W has " +
                std::to_string(W.rows()) + "; pass one observation per row of W");
  }
  if (!W.allFinite()) {
    for (Eigen::Index i = 0; i < W.rows(); ++i) {
      if (!W.row(i).allFinite()) {
        throw Error("W row " + std::to_string(rows_ + i) +
                    " contains NaN or Inf; remove or repair that sample");
      }
    }
  }
  if (!y.allFinite()) {
    for (Eigen::Index i = 0; i < y.size(); ++i) {
      if (!std::isfinite(y(i))) {
        throw Error("y row " + std::to_string(rows_ + i) +
                    " is NaN or Inf; remove or repair that sample");
      }
    }
  }
}

void StreamingLeastSquares::append_group(int group, const Eigen::Ref<const Eigen::MatrixXd>& W,
                                         const Eigen::Ref<const Eigen::VectorXd>& y,
                                         const std::vector<Eigen::Index>& rows) {
  const Eigen::Index b = static_cast<Eigen::Index>(rows.size());
  auto B = scratch_.topRows(b);
  for (Eigen::Index k = 0; k < b; ++k) {
    B.row(k).head(parameters_) = W.row(rows[k]);
    B(k, parameters_) = y(rows[k]);
  }
  triangular_append(factors_[group], B, work_);
  group_rows_[group] += b;
}

void StreamingLeastSquares::add(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y) {
  check_block(W, y);
  const Eigen::Index G = groups();
  for (Eigen::Index start = 0; start < W.rows(); start += kChunk) {
    const Eigen::Index end = std::min(W.rows(), start + kChunk);
    for (auto& r : chunk_rows_) r.clear();
    for (Eigen::Index i = start; i < end; ++i) chunk_rows_[(rows_ + i) % G].push_back(i);
    for (int g = 0; g < G; ++g) {
      if (!chunk_rows_[g].empty()) append_group(g, W, y, chunk_rows_[g]);
    }
  }
  rows_ += W.rows();
}

void StreamingLeastSquares::add(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const Eigen::Ref<const Eigen::VectorXi>& groups) {
  check_block(W, y);
  if (groups.size() != W.rows()) {
    throw Error("groups has " + std::to_string(groups.size()) + " entries but W has " +
                std::to_string(W.rows()) + " rows; pass one group index per row");
  }
  const int G = this->groups();
  for (Eigen::Index i = 0; i < groups.size(); ++i) {
    if (groups(i) < 0 || groups(i) >= G) {
      throw Error("groups row " + std::to_string(rows_ + i) + " is " + std::to_string(groups(i)) +
                  " but must be in [0, " + std::to_string(G) + "); use the joint index of the row");
    }
  }
  for (Eigen::Index start = 0; start < W.rows(); start += kChunk) {
    const Eigen::Index end = std::min(W.rows(), start + kChunk);
    for (auto& r : chunk_rows_) r.clear();
    for (Eigen::Index i = start; i < end; ++i) chunk_rows_[groups(i)].push_back(i);
    for (int g = 0; g < G; ++g) {
      if (!chunk_rows_[g].empty()) append_group(g, W, y, chunk_rows_[g]);
    }
  }
  rows_ += W.rows();
}

const Eigen::MatrixXd& StreamingLeastSquares::group_factor(int group) const {
  if (group < 0 || group >= groups()) {
    throw Error("group " + std::to_string(group) + " is outside [0, " + std::to_string(groups()) +
                "); pass a valid group index");
  }
  return factors_[group];
}

Eigen::MatrixXd StreamingLeastSquares::factor() const {
  const Eigen::Index q = parameters_ + 1;
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(q, q);
  Eigen::MatrixXd B(q, q);
  Eigen::RowVectorXd work(q);
  for (const auto& f : factors_) {
    B = f;
    triangular_append(R, B, work);
  }
  return R;
}

Estimate StreamingLeastSquares::solve(const Eigen::VectorXd& weights, EstimatorKind kind,
                                      const EstimationOptions& options) const {
  const Eigen::Index p = parameters_, q = p + 1, m = rows_;
  check_names(options, p);
  if (m < p) {
    throw Error("W has " + std::to_string(m) + " rows for " + std::to_string(p) +
                " parameters; at least " + std::to_string(p) + " rows (" + std::to_string(p + 1) +
                " for the statistics) are needed: add samples");
  }
  const int G = groups();
  // Combined factor of the weighted rows: rows of group g scaled by weights(g).
  Eigen::MatrixXd R = Eigen::MatrixXd::Zero(q, q);
  {
    Eigen::MatrixXd B(q, q);
    Eigen::RowVectorXd work(q);
    for (int g = 0; g < G; ++g) {
      if (group_rows_[g] == 0) continue;
      B = weights(g) * factors_[g];
      triangular_append(R, B, work);
    }
  }
  const auto s = solve_factor(R, m, options);

  Estimate e;
  e.x = s.x;
  e.singular_values = s.singular_values;
  e.unidentifiable = s.unidentifiable;
  e.dependent_columns = s.dependent_columns;
  e.summary.estimator = kind;
  e.summary.rows = m;
  e.summary.columns = p;
  e.summary.rank = s.rank;
  e.summary.rank_tolerance = s.tolerance;
  e.summary.condition_number = s.condition_number;
  e.summary.passes = 1;

  // Residuals per group from the factors: ‖e_g‖ = ‖R_g·[x; −1]‖, ‖y_g‖ = ‖R_g(:, p)‖ (Q_g is
  // orthogonal).
  Eigen::VectorXd xa(q);
  xa.head(p) = s.x;
  xa(p) = -1.0;
  e.group_rows.resize(G);
  e.group_rms.resize(G);
  e.group_relative_error.resize(G);
  e.group_variance.resize(G);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double rss = 0.0, rss_weighted = 0.0, yy = 0.0;
  for (int g = 0; g < G; ++g) {
    const auto& Rg = factors_[g];
    const double mg = double(group_rows_[g]);
    e.group_rows(g) = mg;
    if (group_rows_[g] == 0) {
      e.group_rms(g) = e.group_relative_error(g) = e.group_variance(g) = nan;
      continue;
    }
    const double eg2 = (Rg.triangularView<Eigen::Upper>() * xa).squaredNorm();
    const double yg2 = Rg.col(p).squaredNorm();
    rss += eg2;
    rss_weighted += weights(g) * weights(g) * eg2;
    yy += yg2;
    e.group_rms(g) = std::sqrt(eg2 / mg);
    e.group_relative_error(g) = yg2 > 0.0 ? std::sqrt(eg2 / yg2) : (eg2 > 0.0 ? nan : 0.0);
    // Gautier: σ_g² from the least-squares solution of the subsystem of group g alone,
    // ‖y_g − W_g x_g‖²/(m_g − rank W_g), unbiased whatever the noise of the other groups.
    const auto sg = solve_factor(Rg, group_rows_[g], options);
    Eigen::VectorXd xg(q);
    xg.head(p) = sg.x;
    xg(p) = -1.0;
    const Eigen::Index dof_g = group_rows_[g] - sg.rank;
    e.group_variance(g) =
        dof_g > 0 ? (Rg.triangularView<Eigen::Upper>() * xg).squaredNorm() / double(dof_g) : nan;
  }
  e.residual_rms = std::sqrt(rss / double(m));
  e.relative_error = yy > 0.0 ? std::sqrt(rss / yy) : (rss > 0.0 ? nan : 0.0);
  e.degrees_of_freedom = m - s.rank;
  e.residual_variance =
      e.degrees_of_freedom > 0 ? rss_weighted / double(e.degrees_of_freedom) : nan;
  // Gautier: C = σ²(WᵀW)⁻¹ = σ²·R⁻¹R⁻ᵀ (pseudo-inverse when rank deficient).
  e.covariance = e.residual_variance * (s.g * s.g.transpose());
  fill_parameter_statistics(e, options);

  if (s.rank < p) {
    e.summary.warnings.push_back(
        "W is rank deficient (rank " + std::to_string(s.rank) + " < " + std::to_string(p) +
        "): parameters " + column_list(options, s.unidentifiable) +
        " are not identifiable individually; regroup them into base parameters or drop " +
        column_list(options, s.dependent_columns));
  }
  if (s.condition_number > options.condition_warning) {
    e.summary.warnings.push_back("condition number " + std::to_string(s.condition_number) +
                                 " exceeds " + std::to_string(options.condition_warning) +
                                 ": the data excite some parameters poorly");
    if (s.rank == p) {
      // Parameters dominating the weakest singular direction.
      for (Eigen::Index j = 0; j < p; ++j) {
        if (std::abs(s.v(j, p - 1)) >= options.weak_direction_threshold) {
          e.poorly_excited.push_back(j);
        }
      }
      std::sort(e.poorly_excited.begin(), e.poorly_excited.end());
      e.poorly_excited.erase(std::unique(e.poorly_excited.begin(), e.poorly_excited.end()),
                             e.poorly_excited.end());
    }
  }
  std::vector<Eigen::Index> poor;
  for (Eigen::Index j : e.poorly_excited) {
    if (std::find(e.unidentifiable.begin(), e.unidentifiable.end(), j) == e.unidentifiable.end())
      poor.push_back(j);
  }
  if (!poor.empty()) {
    e.summary.warnings.push_back("poorly excited parameters: " + column_list(options, poor));
  }
  return e;
}

Estimate StreamingLeastSquares::solve_ordinary(const EstimationOptions& options) const {
  return solve(Eigen::VectorXd::Ones(groups()), EstimatorKind::kOrdinaryLeastSquares, options);
}

Estimate StreamingLeastSquares::solve_weighted(const Eigen::Ref<const Eigen::VectorXd>& group_std,
                                               const EstimationOptions& options) const {
  if (group_std.size() != groups()) {
    throw Error("group_std has " + std::to_string(group_std.size()) + " entries for " +
                std::to_string(groups()) + " groups; pass one standard deviation per group");
  }
  for (int g = 0; g < groups(); ++g) {
    if (!(group_std(g) > 0.0) || !std::isfinite(group_std(g))) {
      throw Error("group_std(" + std::to_string(g) + ") is " + std::to_string(group_std(g)) +
                  "; pass a positive finite noise standard deviation");
    }
  }
  Estimate e = solve(group_std.cwiseInverse(), EstimatorKind::kWeightedLeastSquares, options);
  e.group_variance = group_std.cwiseAbs2();
  return e;
}

Estimate StreamingLeastSquares::solve_weighted(const EstimationOptions& options) const {
  const int G = groups();
  // Step 1 (Gautier): OLS of each group's subsystem gives σ_g² (Estimate::group_variance).
  const Estimate ols = solve_ordinary(options);
  std::vector<std::string> warnings;
  Eigen::VectorXd variance = ols.group_variance;
  double vmax = 0.0;
  for (int g = 0; g < G; ++g) {
    if (group_rows_[g] == 0) continue;
    if (!std::isfinite(variance(g))) {
      variance(g) = ols.residual_variance;  // too few rows in the group: pooled variance
      warnings.push_back("group " + std::to_string(g) +
                         " has too few rows to estimate its noise variance; used the pooled one");
    }
    if (std::isfinite(variance(g))) vmax = std::max(vmax, variance(g));
  }
  // Step 2: rows of group g divided by σ_g, solved again.
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(G);
  if (vmax > 0.0 && std::isfinite(vmax)) {
    for (int g = 0; g < G; ++g) {
      if (group_rows_[g] == 0) continue;
      if (!(variance(g) >= kVarianceFloor * vmax)) {
        variance(g) = kVarianceFloor * vmax;
        warnings.push_back("group " + std::to_string(g) +
                           " has a (near) zero residual variance; its weight was bounded");
      }
      weights(g) = 1.0 / std::sqrt(variance(g));
    }
  } else {
    warnings.push_back("all residuals are zero: weighted least squares equals OLS");
  }
  Estimate e = solve(weights, EstimatorKind::kWeightedLeastSquares, options);
  e.group_variance = variance;
  e.summary.passes = 2;
  e.summary.warnings.insert(e.summary.warnings.begin(), warnings.begin(), warnings.end());
  return e;
}

}  // namespace dynid
