#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"

namespace dynid {

/// Kinetic energy E_k = ½ dqᵀ M(q) dq, including the actuators' ½ Ia·dq² [J].
double kinetic_energy(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq);

/// Potential energy E_p = −Σ_j gᵀ(m_j p_WJ + R_WJ·mc_j) [J], zero at the base origin.
double potential_energy(const Model& model, Workspace& ws,
                        const Eigen::Ref<const Eigen::VectorXd>& q);

}  // namespace dynid
