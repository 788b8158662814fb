#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"

namespace dynid {

/// Analytic partial derivatives of the inverse dynamics tau = rnea(q, dq, ddq, options):
/// partial_q = ∂tau/∂q, partial_dq = ∂tau/∂q̇, partial_ddq = ∂tau/∂q̈ = M(q) (+ Ia on the
/// diagonal when options.joint_terms, as rnea). All n×n, row i = joint i's torque or force, column
/// k = the variable of joint k (N·m/rad, N·m·s/rad, kg·m² and their prismatic counterparts).
/// With the joint terms, ∂/∂q̇ includes Fv + Fva·sign(q̇); the Coulomb step has no derivative
/// (taken as 0, its value away from q̇ = 0), nor has |q̇| at 0 (taken as 0).
/// Method: the recursive world-frame derivatives of Carpentier & Mansard 2018 ("Analytical
/// derivatives of rigid body dynamics algorithms", RSS), in the form derived in
/// docs/methods/dynamics.md "RNEA derivatives": one forward pass for the kinematics and the
/// bodies' inertias, momenta, forces and inertia rates, one backward pass over composite
/// quantities, then two 6-vector products per (joint, ancestor) pair: O(n + Σ depth).
/// No allocation; sizes are checked with assertions only (hot path).
void rnea_derivatives(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& ddq,
                      Eigen::Ref<Eigen::MatrixXd> partial_q, Eigen::Ref<Eigen::MatrixXd> partial_dq,
                      Eigen::Ref<Eigen::MatrixXd> partial_ddq, const RneaOptions& options = {});

}  // namespace dynid
