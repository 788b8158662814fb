#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// Energy regressor row h(q, dq) with H = E_k + E_p = h · theta (seed 1 eqs. 6–7 and 12; seed 2
/// eqs. 4–5). Size layout.columns(n); friction and offset columns are zero (they do no
/// conservative work), the armature column is ½·dq_j².
void energy_regressor(const Model& model, Workspace& ws, const ParameterLayout& layout,
                      const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq, Eigen::Ref<Eigen::VectorXd> h);

/// Integral (energy) model over a sampled interval (seed 1 eqs. 8–18):
/// y = ∫ tauᵀ dq dt = d · theta, with d = h(t_end) − h(t_begin) plus the friction-work columns
/// ∫ dq_j² dt (Fv), ∫ |dq_j| dt (Fc), ∫ dq_j dt (Fo), each step by step_velocity_integrals (exact
/// for q cubic over the step); asymmetric columns split those integrals by the sign of dq_j. y by
/// the trapezoidal rule. t: size m ≥ 2, strictly increasing [s]; q, dq: m × n
/// (one sample per row). Returns y through `y` and the row through `d`.
void integral_regressor(const Model& model, Workspace& ws, const ParameterLayout& layout,
                        const Eigen::Ref<const Eigen::VectorXd>& t,
                        const Eigen::Ref<const Eigen::MatrixXd>& q,
                        const Eigen::Ref<const Eigen::MatrixXd>& dq,
                        const Eigen::Ref<const Eigen::MatrixXd>& tau, double& y,
                        Eigen::Ref<Eigen::VectorXd> d);

}  // namespace dynid
