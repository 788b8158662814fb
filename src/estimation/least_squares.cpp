#include "dynid/estimation/least_squares.hpp"

#include <string>

#include "dynid/common/error.hpp"
#include "dynid/estimation/streaming_least_squares.hpp"

namespace dynid {

namespace {

// Checks the sizes a batch estimator needs before anything is accumulated.
void check_batch(const Eigen::Ref<const Eigen::MatrixXd>& W,
                 const Eigen::Ref<const Eigen::VectorXd>& y,
                 const Eigen::Ref<const Eigen::VectorXi>& groups, bool groups_required) {
  if (W.cols() == 0) {
    throw Error("W has no columns; pass a regressor with at least one parameter column");
  }
  if (y.size() != W.rows()) {
    throw Error("y has " + std::to_string(y.size()) + " rows but W has " +
                std::to_string(W.rows()) + "; pass one observation per row of W");
  }
  if ((groups_required || groups.size() > 0) && groups.size() != W.rows()) {
    throw Error("groups has " + std::to_string(groups.size()) + " entries but W has " +
                std::to_string(W.rows()) +
                " rows; pass one group index per row (joint_row_groups for torques)");
  }
  if (W.rows() < W.cols()) {
    throw Error("W has " + std::to_string(W.rows()) + " rows for " + std::to_string(W.cols()) +
                " parameters; at least " + std::to_string(W.cols()) + " rows (" +
                std::to_string(W.cols() + 1) + " for the statistics) are needed: add samples");
  }
  for (Eigen::Index i = 0; i < groups.size(); ++i) {
    if (groups(i) < 0) {
      throw Error("groups row " + std::to_string(i) + " is " + std::to_string(groups(i)) +
                  "; group indices must be >= 0 (use the joint index of the row)");
    }
  }
}

}  // namespace

Eigen::VectorXi joint_row_groups(Eigen::Index rows, int joints) {
  if (joints < 1) {
    throw Error("joints is " + std::to_string(joints) +
                "; a torque regressor has at least 1 joint");
  }
  Eigen::VectorXi g(rows);
  for (Eigen::Index r = 0; r < rows; ++r) g(r) = static_cast<int>(r % joints);
  return g;
}

Estimate ordinary_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const Eigen::Ref<const Eigen::VectorXi>& groups,
                                const EstimationOptions& options) {
  check_batch(W, y, groups, false);
  if (groups.size() == 0) {
    StreamingLeastSquares s(W.cols(), 1);
    s.add(W, y);
    return s.solve_ordinary(options);
  }
  StreamingLeastSquares s(W.cols(), groups.maxCoeff() + 1);
  s.add(W, y, groups);
  return s.solve_ordinary(options);
}

Estimate weighted_least_squares(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const Eigen::Ref<const Eigen::VectorXi>& groups,
                                const EstimationOptions& options) {
  check_batch(W, y, groups, true);
  StreamingLeastSquares s(W.cols(), groups.size() > 0 ? groups.maxCoeff() + 1 : 1);
  s.add(W, y, groups);
  return s.solve_weighted(options);
}

}  // namespace dynid
