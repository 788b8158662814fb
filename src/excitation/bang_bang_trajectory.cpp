#include "dynid/excitation/bang_bang_trajectory.hpp"

#include "excitation/move_timing.hpp"

namespace dynid {

BangBangTrajectory::BangBangTrajectory(const Eigen::MatrixXd& way_points,
                                       const Eigen::VectorXd& a_max, double dwell) {
  using namespace excitation_detail;
  check_way_points(way_points, "bang-bang way_points");
  check_positive(a_max, way_points.rows(), "bang-bang a_max");
  for (Eigen::Index k = 0; k + 1 < way_points.cols(); ++k)
    moves_.push_back(
        bang_bang_move(way_points.col(k), way_points.col(k + 1), a_max, static_cast<int>(k)));
  finish(way_points.col(0), dwell);
}

}  // namespace dynid
