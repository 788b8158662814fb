#pragma once

#include <memory>

#include "dynid/sim/plant.hpp"

namespace dynid::detail {

/// The native RK4 engine (src/sim/native_plant.cpp).
std::unique_ptr<Plant> make_native_plant(const Model& model, double dt,
                                         const NativePlantOptions& options);

/// The MuJoCo engine (src/sim/mujoco_plant.cpp).
std::unique_ptr<Plant> make_mujoco_plant(const Model& model, double dt,
                                         const MujocoPlantOptions& options);

/// Throws dynid::Error unless q0 and dq0 have n finite entries.
void check_state(int n, const Eigen::Ref<const Eigen::VectorXd>& q0,
                 const Eigen::Ref<const Eigen::VectorXd>& dq0);

/// Throws dynid::Error unless tau has n finite entries.
void check_torque(int n, const Eigen::Ref<const Eigen::VectorXd>& tau);

}  // namespace dynid::detail
