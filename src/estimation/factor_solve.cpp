#include "factor_solve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "dynid/common/error.hpp"

namespace dynid {
namespace estimation_detail {

namespace {
// A column is unidentifiable when its row of the null-space basis has at least this norm (exact
// dependencies give O(1) values; numerical noise gives O(ε·cond)).
constexpr double kNullSpaceRowTolerance = 1e-6;
}  // namespace

std::string column_name(const EstimationOptions& options, Eigen::Index j) {
  if (j < static_cast<Eigen::Index>(options.names.size())) return options.names[j];
  return "x" + std::to_string(j);
}

std::string column_list(const EstimationOptions& options, const std::vector<Eigen::Index>& cols) {
  std::string out;
  for (std::size_t i = 0; i < cols.size(); ++i) {
    if (i) out += ", ";
    out += column_name(options, cols[i]);
  }
  return out;
}

void check_sizes(const Eigen::Ref<const Eigen::MatrixXd>& W,
                 const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index p) {
  if (W.cols() != p) {
    throw Error("W has " + std::to_string(W.cols()) + " columns but the estimator has " +
                std::to_string(p) + " parameters; pass one column per parameter");
  }
  if (y.size() != W.rows()) {
    throw Error("y has " + std::to_string(y.size()) + " rows but W has " +
                std::to_string(W.rows()) + "; pass one observation per row of W");
  }
}

void check_names(const EstimationOptions& options, Eigen::Index p) {
  if (!options.names.empty() && static_cast<Eigen::Index>(options.names.size()) != p) {
    throw Error("EstimationOptions::names has " + std::to_string(options.names.size()) +
                " entries but W has " + std::to_string(p) +
                " columns; pass one name per column or none");
  }
}

void triangular_append(Eigen::MatrixXd& R, Eigen::Ref<Eigen::MatrixXd> B,
                       Eigen::RowVectorXd& work) {
  const Eigen::Index q = R.cols();
  for (Eigen::Index k = 0; k < q; ++k) {
    auto bk = B.col(k);
    const double tail = bk.squaredNorm();
    if (tail == 0.0) continue;
    // Householder vector v = [r − α; b_k] with α = −sign(r)·‖[r; b_k]‖ (no cancellation).
    const double r = R(k, k);
    const double s = std::hypot(r, std::sqrt(tail));
    const double alpha = r >= 0.0 ? -s : s;
    const double v0 = r - alpha;
    const double vtv = v0 * v0 + tail;
    const Eigen::Index rest = q - k - 1;
    if (rest > 0) {
      auto w = work.head(rest);
      w.noalias() = bk.transpose() * B.rightCols(rest);
      w += v0 * R.row(k).tail(rest);
      w *= 2.0 / vtv;
      R.row(k).tail(rest) -= v0 * w;
      B.rightCols(rest).noalias() -= bk * w;
    }
    R(k, k) = alpha;
    bk.setZero();
  }
}

FactorSolution solve_factor(const Eigen::MatrixXd& R, Eigen::Index m,
                            const EstimationOptions& options) {
  const Eigen::Index p = R.cols() - 1;
  const Eigen::MatrixXd Rp = R.topLeftCorner(p, p).triangularView<Eigen::Upper>();
  const Eigen::VectorXd z = R.col(p).head(p);
  FactorSolution s;
  // RᵀR = WᵀW, so the singular values of R are those of W.
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Rp, Eigen::ComputeFullU | Eigen::ComputeFullV);
  s.singular_values = svd.singularValues();
  s.v = svd.matrixV();
  const double smax = s.singular_values(0);
  const double rel = options.rank_tolerance > 0.0
                         ? options.rank_tolerance
                         : double(std::max(m, p)) * std::numeric_limits<double>::epsilon();
  s.tolerance = rel * smax;
  s.rank = 0;
  for (Eigen::Index i = 0; i < p; ++i) {
    if (s.singular_values(i) > s.tolerance) ++s.rank;
  }
  const double smin = s.singular_values(p - 1);
  s.condition_number = smin > 0.0 ? smax / smin : std::numeric_limits<double>::infinity();
  if (s.rank == p) {
    s.x = Rp.triangularView<Eigen::Upper>().solve(z);
    s.g = Rp.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
    return s;
  }
  const Eigen::Index r = s.rank;
  const Eigen::VectorXd inv = s.singular_values.head(r).cwiseInverse();
  s.g = s.v.leftCols(r) * inv.asDiagonal();
  s.x = s.g * (svd.matrixU().leftCols(r).transpose() * z);
  const Eigen::MatrixXd null = s.v.rightCols(p - r);
  for (Eigen::Index j = 0; j < p; ++j) {
    if (null.row(j).norm() >= kNullSpaceRowTolerance) s.unidentifiable.push_back(j);
  }
  // Column-pivoted QR of R chooses a well-conditioned set of r columns; the rest are dependent.
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Rp);
  for (Eigen::Index k = r; k < p; ++k)
    s.dependent_columns.push_back(qr.colsPermutation().indices()(k));
  std::sort(s.dependent_columns.begin(), s.dependent_columns.end());
  return s;
}

}  // namespace estimation_detail
}  // namespace dynid
