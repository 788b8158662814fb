#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"

namespace dynid {

/// Forward kinematics: fills ws.links[j].{R_PJ, p_PJ, R_WJ, p_WJ} for joint positions q (size n,
/// [rad or m]). Cost O(n), no allocation.
void forward_kinematics(const Model& model, Workspace& ws,
                        const Eigen::Ref<const Eigen::VectorXd>& q);

/// Forward kinematics with first- and second-order terms: also fills w, v, dw and a of every link
/// in its own frame. With `with_gravity` the base acceleration is −g (so `a` is the proper
/// acceleration a − g·R_WJᵀ, as the RNEA and the load model want); otherwise the true acceleration.
void forward_kinematics(const Model& model, Workspace& ws,
                        const Eigen::Ref<const Eigen::VectorXd>& q,
                        const Eigen::Ref<const Eigen::VectorXd>& dq,
                        const Eigen::Ref<const Eigen::VectorXd>& ddq, bool with_gravity);

}  // namespace dynid
