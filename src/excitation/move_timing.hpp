#pragma once

// Internal helpers shared by the trapezoidal, bang-bang and slope trajectories.

#include <string>

#include <Eigen/Core>

#include "dynid/excitation/move_sequence.hpp"

namespace dynid::excitation_detail {

/// Throws unless v has size n and every entry is finite and > 0.
void check_positive(const Eigen::VectorXd& v, Eigen::Index n, const std::string& name);

/// Throws unless the way-point matrix is n×m with m ≥ 2 and finite.
void check_way_points(const Eigen::MatrixXd& way_points, const std::string& name);

/// Synchronised trapezoidal move from -> to (see TrapezoidalTrajectory); start_time is left 0.
Move trapezoid_move(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                    const Eigen::VectorXd& v_max, const Eigen::VectorXd& a_max, int index);

/// Synchronised bang-bang move from -> to (see BangBangTrajectory); start_time is left 0.
Move bang_bang_move(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                    const Eigen::VectorXd& a_max, int index);

}  // namespace dynid::excitation_detail
