#include "dynid/excitation/slope_trajectory.hpp"

#include <algorithm>
#include <string>

#include "dynid/common/error.hpp"
#include "excitation/move_timing.hpp"

namespace dynid {

SlopeTrajectory::SlopeTrajectory(const Eigen::VectorXd& q_from, const Eigen::VectorXd& q_to,
                                 const Eigen::VectorXd& velocity,
                                 const Eigen::VectorXd& acceleration, int cycles, double dwell) {
  using namespace excitation_detail;
  if (cycles < 1)
    throw Error("slope cycles: need at least 1 back-and-forth cycle, got " +
                std::to_string(cycles));
  if (q_from.size() < 1 || q_to.size() != q_from.size())
    throw Error("slope q_from/q_to: need the same number (>= 1) of joints, got " +
                std::to_string(q_from.size()) + " and " + std::to_string(q_to.size()));
  if (!q_from.allFinite() || !q_to.allFinite())
    throw Error("slope q_from/q_to: NaN or Inf; give finite joint positions");
  check_positive(velocity, q_from.size(), "slope velocity");
  check_positive(acceleration, q_from.size(), "slope acceleration");
  for (int c = 0; c < cycles; ++c) {
    moves_.push_back(trapezoid_move(q_from, q_to, velocity, acceleration, 2 * c));
    moves_.push_back(trapezoid_move(q_to, q_from, velocity, acceleration, 2 * c + 1));
  }
  finish(q_from, dwell);
}

std::vector<std::pair<double, double>> SlopeTrajectory::constant_velocity_intervals() const {
  std::vector<std::pair<double, double>> out;
  for (const Move& m : moves_) {
    const double ta = m.accel_time.maxCoeff();
    out.emplace_back(m.start_time + ta, m.start_time + m.duration - ta);
  }
  return out;
}

}  // namespace dynid
