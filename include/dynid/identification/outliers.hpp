#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"
#include "dynid/identification/outlier_options.hpp"
#include "dynid/identification/record.hpp"

namespace dynid {

/// One flagged torque sample.
struct TorqueOutlier {
  Eigen::Index sample = 0;    ///< row of the record (0-based)
  Eigen::Index joint = 0;     ///< column (0-based)
  double value = 0.0;         ///< the logged torque [N·m or N]
  double local_median = 0.0;  ///< median of its window, the replacement under kDrop
};

/// Gross outliers of each torque column: samples further than threshold × scale from the median
/// of their 2·half_window+1 neighbours (Hampel; robust statistics, Huber 1981). Steps (Coulomb
/// friction at a velocity reversal) pass: a running median keeps edges. tau: m × n. Sorted by
/// sample, then joint. No throw.
std::vector<TorqueOutlier> find_torque_outliers(const Eigen::Ref<const Eigen::MatrixXd>& tau,
                                                const OutlierOptions& options = {});

/// A run checked before identification, and what was found.
struct ScreenedRun {
  JointRecord record;                   ///< the input, with outliers replaced under kDrop
  std::vector<TorqueOutlier> outliers;  ///< gross torque outliers found
  std::vector<std::string> warnings;    ///< named, one line each (plausibility, outliers)
};

/// check_run_plausibility() (signal/plausibility.hpp) and find_torque_outliers() on a joint-side
/// run of `model`, applying options.policy. Throws dynid::Error as check_run_plausibility.
ScreenedRun screen_run(const Model& model, const JointRecord& record,
                       const OutlierOptions& options);

/// Throws dynid::Error when the estimate or its residual variance is not finite, naming the
/// likely input at fault (the outliers `screened` found, or the largest |tau|) and the fix.
void check_finite_estimate(const Estimate& estimate, const ScreenedRun& screened);

}  // namespace dynid
