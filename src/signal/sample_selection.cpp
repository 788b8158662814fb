#include "dynid/signal/sample_selection.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "dynid/common/error.hpp"

namespace dynid {

Eigen::MatrixXd trim_edges(const Eigen::Ref<const Eigen::MatrixXd>& x, int first, int last) {
  if (first < 0 || last < 0) {
    throw Error("trim counts are " + std::to_string(first) + " and " + std::to_string(last) +
                ": give non-negative numbers of samples to drop");
  }
  const Eigen::Index keep = x.rows() - first - last;
  if (keep < 1) {
    throw Error("trimming " + std::to_string(first) + " + " + std::to_string(last) +
                " samples leaves nothing of the " + std::to_string(x.rows()) +
                " samples: trim less or give a longer record");
  }
  return x.middleRows(first, keep);
}

RowMask moving_sample_mask(const Eigen::Ref<const Eigen::MatrixXd>& dq,
                           const Eigen::Ref<const Eigen::VectorXd>& thresholds) {
  const Eigen::Index n = dq.cols();
  if (thresholds.size() != 1 && thresholds.size() != n) {
    throw Error("velocity thresholds have " + std::to_string(thresholds.size()) + " values for " +
                std::to_string(n) + " joints: give one per joint or one for all");
  }
  for (Eigen::Index j = 0; j < thresholds.size(); ++j) {
    if (!(thresholds(j) >= 0.0)) {
      std::ostringstream msg;
      msg << "velocity threshold " << j << " is " << thresholds(j)
          << ": give a non-negative speed below which samples are dropped";
      throw Error(msg.str());
    }
  }
  RowMask mask(dq.rows(), n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double th = thresholds.size() == 1 ? thresholds(0) : thresholds(j);
    mask.col(j) = dq.col(j).array().abs() >= th;
  }
  return mask;
}

}  // namespace dynid
