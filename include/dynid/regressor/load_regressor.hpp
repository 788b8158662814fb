#pragma once

#include <Eigen/Core>

namespace dynid {

/// Load-wrench regressor K (6×10) of seed 1 eq. 28: W = [F; N] = K · phi, the force and moment
/// (about sensor origin P) that the force/torque sensor exerts on the load, in the sensor frame.
/// phi = [m, mcx, mcy, mcz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz] about P in the sensor frame.
/// Inputs, all in the sensor frame: w [rad/s], dw [rad/s²], ddp = linear acceleration of P [m/s²],
/// g_S = gravity expressed in the sensor frame (R_SWᵀ·g_W) [m/s²].
Eigen::Matrix<double, 6, 10> load_regressor(const Eigen::Vector3d& w, const Eigen::Vector3d& dw,
                                            const Eigen::Vector3d& ddp, const Eigen::Vector3d& g_S);

}  // namespace dynid
