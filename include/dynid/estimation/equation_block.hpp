#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// A block of linear equations y = W·θ over named standard columns: the one data type between the
/// "equations" stage of the identification pipeline and its "stack" and "estimate" stages
/// (docs/design.md §8). An equations builder (differential: one row per joint and sample, seed 1
/// eq. 5 / seed 2 eq. 9; integral: one row per energy interval, seed 1 eqs. 15–17; load: one row
/// per wrench component and sample, seed 1 eq. 28) turns one processed run into a block; blocks of
/// several runs are stacked; the estimators see only blocks.
struct EquationBlock {
  /// rows × columns regressor over the standard columns named in `columns` (for a robot model,
  /// stacked_regressor_names() order, so base-parameter selection applies unchanged).
  Eigen::MatrixXd W;
  /// rows: the measured side (joint torque [N·m or N], actuator work [J], wrench component, …).
  Eigen::VectorXd y;
  /// Per row, its row group in [0, group_names.size()): rows of one group share one noise variance
  /// (WLS estimates one per group; statistics report per group), e.g. the joint of a torque row.
  Eigen::VectorXi group;
  /// Per row, the time sample (or interval) it belongs to, non-decreasing within a run: rows of one
  /// sample are errors at the same instant, so the HAC covariance sums them before weighting lags.
  Eigen::VectorXi sample;
  /// Per row, its time [s] (the end of the interval for integral rows): RLS histories, plots.
  Eigen::VectorXd t;
  std::vector<std::string> columns;      ///< names of W's columns
  std::vector<std::string> group_names;  ///< e.g. the joint names, or "energy"
};

}  // namespace dynid
