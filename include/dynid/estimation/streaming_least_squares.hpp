#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"

namespace dynid {

/// Least squares of y = W·x + e accumulated block by block in O(G·(p+1)²) memory, independent of
/// the number of rows: for every row group g (joint) it keeps the upper-triangular factor R_g of
/// [W_g y_g] (the "extra column" trick: R_g = [R_gp z_g; 0 ρ_g], R_gpᵀR_gp = W_gᵀW_g,
/// R_gpᵀz_g = W_gᵀy_g), updated by Householder QR of [R_g; new rows] (Golub–Van Loan §6.5;
/// seed 1 eq. 35 solved without forming WᵀW). The combined factor of all groups gives OLS; the
/// per-group factors give exact per-group residuals, variances and WLS in the same single pass.
class StreamingLeastSquares {
 public:
  /// p = parameters (columns of W) ≥ 1, G = groups ≥ 1. Throws dynid::Error otherwise.
  explicit StreamingLeastSquares(Eigen::Index parameters, int groups = 1);

  /// Adds rows; row r of the whole stream (counted from the first row ever added) belongs to
  /// group r mod G (sample-major torque regressor: group = joint). W is b×p, y has b entries.
  /// Throws dynid::Error on wrong sizes or NaN/Inf (naming the stream row).
  void add(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& y);

  /// Adds rows with explicit group indices in [0, G). Same errors, plus out-of-range groups.
  void add(const Eigen::Ref<const Eigen::MatrixXd>& W, const Eigen::Ref<const Eigen::VectorXd>& y,
           const Eigen::Ref<const Eigen::VectorXi>& groups);

  /// Ordinary least squares from the accumulated factor (rank, condition number, statistics).
  /// Throws dynid::Error if fewer rows than parameters were added.
  Estimate solve_ordinary(const EstimationOptions& options = {}) const;

  /// Gautier's two-step weighted least squares: σ_g² from the OLS of each group's rows alone, then
  /// rows of group g divided by σ_g and all solved again. Same errors as solve_ordinary.
  Estimate solve_weighted(const EstimationOptions& options = {}) const;

  /// Least squares with known per-group noise standard deviations (rows of g divided by σ_g > 0).
  /// Throws dynid::Error on a size mismatch or a non-positive / non-finite σ_g.
  Estimate solve_weighted(const Eigen::Ref<const Eigen::VectorXd>& group_std,
                          const EstimationOptions& options = {}) const;

  /// Upper-triangular (p+1)×(p+1) factor of [W y] over all groups, with unit group weights.
  Eigen::MatrixXd factor() const;
  /// Upper-triangular (p+1)×(p+1) factor of [W_g y_g] of group g.
  const Eigen::MatrixXd& group_factor(int group) const;

  Eigen::Index rows() const { return rows_; }                       ///< rows added so far
  Eigen::Index parameters() const { return parameters_; }           ///< p
  int groups() const { return static_cast<int>(factors_.size()); }  ///< G
  /// Rows added per group.
  const std::vector<Eigen::Index>& group_rows() const { return group_rows_; }
  /// Forgets all rows (keeps sizes).
  void reset();

 private:
  void check_block(const Eigen::Ref<const Eigen::MatrixXd>& W,
                   const Eigen::Ref<const Eigen::VectorXd>& y) const;
  void append_group(int group, const Eigen::Ref<const Eigen::MatrixXd>& W,
                    const Eigen::Ref<const Eigen::VectorXd>& y,
                    const std::vector<Eigen::Index>& rows);
  Estimate solve(const Eigen::VectorXd& weights, EstimatorKind kind,
                 const EstimationOptions& options) const;

  Eigen::Index parameters_;
  Eigen::Index rows_ = 0;
  std::vector<Eigen::MatrixXd> factors_;  // R_g, (p+1)×(p+1) upper triangular
  std::vector<Eigen::Index> group_rows_;
  Eigen::MatrixXd scratch_;  // gathered rows of one group, ≤ kChunk × (p+1)
  Eigen::RowVectorXd work_;  // Householder workspace
  std::vector<std::vector<Eigen::Index>> chunk_rows_;  // row indices per group in a chunk
};

}  // namespace dynid
