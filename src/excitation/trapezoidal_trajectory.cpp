#include "dynid/excitation/trapezoidal_trajectory.hpp"

#include "excitation/move_timing.hpp"

namespace dynid {

TrapezoidalTrajectory::TrapezoidalTrajectory(const Eigen::MatrixXd& way_points,
                                             const Eigen::VectorXd& v_max,
                                             const Eigen::VectorXd& a_max, double dwell) {
  using namespace excitation_detail;
  check_way_points(way_points, "trapezoidal way_points");
  check_positive(v_max, way_points.rows(), "trapezoidal v_max");
  check_positive(a_max, way_points.rows(), "trapezoidal a_max");
  for (Eigen::Index k = 0; k + 1 < way_points.cols(); ++k)
    moves_.push_back(trapezoid_move(way_points.col(k), way_points.col(k + 1), v_max, a_max,
                                    static_cast<int>(k)));
  finish(way_points.col(0), dwell);
}

}  // namespace dynid
