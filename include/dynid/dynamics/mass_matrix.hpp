#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"

namespace dynid {

/// Joint-space mass matrix M(q) (n×n, symmetric positive definite) by the composite-rigid-body
/// algorithm (Featherstone 2008, §6.2), including the actuator inertias Ia on the diagonal.
/// Identity: M·ddq + rnea(q, dq, 0) = rnea(q, dq, ddq).
void mass_matrix(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                 Eigen::Ref<Eigen::MatrixXd> M);

/// Forward dynamics: ddq = M⁻¹(tau − rnea(q, dq, 0)), with the joint terms of the model (friction
/// uses sign(dq), Coulomb discontinuous at dq = 0; simulators smooth it themselves).
void forward_dynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> ddq,
                      const RneaOptions& options = {});

}  // namespace dynid
