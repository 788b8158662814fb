#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// Joint-torque regressor (differential model, seed 1 eq. 5; seed 2 eqs. 1–3):
/// tau = Y(q, dq, ddq) · theta with theta = layout.parameters(model), Y of size n ×
/// layout.columns(n) written into the given n-row block. Uses the model's gravity. No allocation.
void torque_regressor(const Model& model, Workspace& ws, const ParameterLayout& layout,
                      const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& ddq, Eigen::Ref<Eigen::MatrixXd> Y);

}  // namespace dynid
