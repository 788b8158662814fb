#pragma once

#include <Eigen/Core>

namespace dynid {

/// Boolean matrix (samples × joints) used as a per-joint row mask.
using RowMask = Eigen::Array<bool, Eigen::Dynamic, Eigen::Dynamic>;

/// Drops the first `first` and last `last` rows of x (e.g. the filter edge transients of filtfilt,
/// a few times the filter's settling time). Returns (m − first − last) × n.
/// Throws dynid::Error for negative counts or if nothing would remain.
Eigen::MatrixXd trim_edges(const Eigen::Ref<const Eigen::MatrixXd>& x, int first, int last);

/// Per-joint mask of the samples whose velocity is far enough from zero to identify Coulomb
/// friction (Fc·sign(dq) is undefined near dq = 0): mask(k, j) = |dq(k, j)| ≥ threshold(j).
/// dq: m × n [rad/s or m/s]; thresholds: n (≥ 0), or one value for all joints. A regressor row of
/// joint j at sample k is kept only when mask(k, j).
/// Throws dynid::Error if the threshold count is neither 1 nor n, or a threshold is negative/NaN.
RowMask moving_sample_mask(const Eigen::Ref<const Eigen::MatrixXd>& dq,
                           const Eigen::Ref<const Eigen::VectorXd>& thresholds);

}  // namespace dynid
