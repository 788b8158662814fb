#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"

namespace dynid {

/// Forward dynamics by the articulated-body algorithm (Featherstone 2008, Table 7.1; O(n)):
/// ddq = M⁻¹(tau − rnea(q, dq, 0, options)), so rnea(q, dq, ddq) = tau with the default options.
/// Semantics as crba_forward_dynamics: the actuator inertia Ia always adds to the joint's inertia
/// (as in mass_matrix); options.joint_terms switches the friction torques Fv·dq + Fc·sign(dq) + Fo
/// (+ asymmetry), options.gravity the model's gravity. q, dq, tau, ddq: size n (rad, m; N·m, N).
/// Derivation: docs/methods/dynamics.md, "Articulated-body algorithm". No allocation; sizes are
/// checked with assertions only (hot path). A singular articulated inertia (a massless leaf
/// without Ia) gives non-finite ddq, as the CRBA path's zero pivot does.
void articulated_body_forward_dynamics(const Model& model, Workspace& ws,
                                       const Eigen::Ref<const Eigen::VectorXd>& q,
                                       const Eigen::Ref<const Eigen::VectorXd>& dq,
                                       const Eigen::Ref<const Eigen::VectorXd>& tau,
                                       Eigen::Ref<Eigen::VectorXd> ddq,
                                       const RneaOptions& options = {});

}  // namespace dynid
