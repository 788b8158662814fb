#pragma once

// Internal helpers of the estimation module (not public API).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"

namespace dynid {
namespace estimation_detail {

/// Name of column j: options.names[j] or "x<j>".
std::string column_name(const EstimationOptions& options, Eigen::Index j);

/// Comma-separated names of the given columns.
std::string column_list(const EstimationOptions& options, const std::vector<Eigen::Index>& cols);

/// Throws dynid::Error unless W has p columns and y one entry per row of W.
void check_sizes(const Eigen::Ref<const Eigen::MatrixXd>& W,
                 const Eigen::Ref<const Eigen::VectorXd>& y, Eigen::Index p);

/// Throws dynid::Error if options.names is neither empty nor of size p.
void check_names(const EstimationOptions& options, Eigen::Index p);

/// Householder triangularisation of [R; B] → [R'; 0] (Golub–Van Loan §5.1/§6.5): R (q×q, upper
/// triangular) is updated in place so that R'ᵀR' = RᵀR + BᵀB; B (b×q) is destroyed. work ≥ q.
void triangular_append(Eigen::MatrixXd& R, Eigen::Ref<Eigen::MatrixXd> B, Eigen::RowVectorXd& work);

/// Solution of the least-squares problem whose [W y] factor is R (q = p+1).
struct FactorSolution {
  Eigen::VectorXd x;                ///< minimum-norm least-squares solution
  Eigen::MatrixXd g;                ///< p×rank, (WᵀW)⁺ = g·gᵀ
  Eigen::VectorXd singular_values;  ///< of W, descending
  Eigen::MatrixXd v;                ///< right singular vectors of W
  Eigen::Index rank = 0;
  double tolerance = 0.0;  ///< absolute singular-value threshold
  double condition_number = 0.0;
  std::vector<Eigen::Index> unidentifiable;
  std::vector<Eigen::Index> dependent_columns;
};

/// Solves from the factor R of [W y] with m rows: SVD of the p×p block for rank, condition number
/// and null space; back substitution when full rank, truncated SVD otherwise; column-pivoted QR
/// for the columns to drop.
FactorSolution solve_factor(const Eigen::MatrixXd& R, Eigen::Index m,
                            const EstimationOptions& options);

}  // namespace estimation_detail
}  // namespace dynid
