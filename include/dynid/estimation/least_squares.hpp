#pragma once

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"

namespace dynid {

/// Row groups of a sample-major torque regressor with `joints` joints: row r belongs to joint
/// r mod joints. Returns a vector of `rows` group indices. Throws dynid::Error if joints < 1.
Eigen::VectorXi joint_row_groups(Eigen::Index rows, int joints);

/// Ordinary least squares x = argmin ‖y − W·x‖ (seed 1 eq. 35) by Householder QR of [W y]
/// (never WᵀW); rank and condition number from the SVD of R (singular values of W), minimum-norm
/// solution and unidentifiable columns when rank deficient, Gautier statistics (σ² = ‖e‖²/(m−r),
/// C = σ²R⁻¹R⁻ᵀ). W is m×p, y has m entries; `groups` (size m, values ≥ 0) only selects the
/// per-group residual statistics (empty: one group).
/// Throws dynid::Error: no columns, size mismatch, NaN/Inf (names the row), m < p.
Estimate ordinary_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const Eigen::Ref<const Eigen::VectorXi>& groups = Eigen::VectorXi(),
                                const EstimationOptions& options = {});

/// Gautier's two-step weighted least squares: per-group noise variance
/// σ_g² = ‖y_g − W_g x_g‖²/(m_g − rank W_g) from the OLS of the rows of group g (joint) alone,
/// rows divided by σ_g, all solved again; statistics of the weighted problem
/// (σ_w² = ‖W̃x − ỹ‖²/(m − r), C = σ_w²(W̃ᵀW̃)⁻¹). groups has m entries ≥ 0
/// (joint_row_groups for a torque regressor). Same errors as ordinary_least_squares.
Estimate weighted_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const Eigen::Ref<const Eigen::VectorXi>& groups,
                                const EstimationOptions& options = {});

}  // namespace dynid
