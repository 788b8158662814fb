#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid {

/// Motor-side positions to joint positions (docs/design.md §3): q = N⁻¹·q_motor + q_offset, row by
/// row. qm: samples × n [motor rad]; returns samples × n [rad or m]. Throws dynid::Error on a
/// column count that is not the model's dof.
Eigen::MatrixXd joint_positions_from_motor(const Model& model,
                                           const Eigen::Ref<const Eigen::MatrixXd>& qm);

/// Motor-side torques to joint torques: tau = Nᵀ·tau_motor, row by row (power is preserved:
/// tau_motorᵀ·dq_motor = tauᵀ·dq). taum: samples × n [N·m]; returns samples × n.
Eigen::MatrixXd joint_torques_from_motor(const Model& model,
                                         const Eigen::Ref<const Eigen::MatrixXd>& taum);

/// Motors whose row of N drives more than one joint (a coupled wrist such as the Stäubli TX40's,
/// where q6_motor = N66·(q5 + q6)); 0-based motor indices.
std::vector<int> coupled_motors(const Model& model);

/// Number of extra regressor columns for the coupled motors: three per coupled motor.
int coupling_columns(const Model& model);

/// Names of the coupling columns: `Iam<k> Fvm<k> Fcm<k>` per coupled motor k (1-based).
std::vector<std::string> coupling_column_names(const Model& model);

/// Regressor columns of the motor-side inertia, viscous and Coulomb friction of the coupled motors,
/// reflected to the joints through the transmission, with the joint-diagonal parts left to the
/// joints' own Ia/Fv columns so that the parameterisation is the one of the TX40 reference
/// (../shared/datasets/staubli-tx40/SOURCE.md): for motor k with row n_k = N_k/s (s = max|N_kj|),
/// row j gets n_kj·Σ_{i≠j} n_ki·ddq_i (Iam), n_kj·Σ_{i≠j} n_ki·dq_i (Fvm) and
/// n_kj·sign(n_k·dq) (Fcm). Values are joint-side (scaled by s²). dq, ddq: n; out: n × 3·(#motors).
void coupling_regressor(const Model& model, const std::vector<int>& motors,
                        const Eigen::Ref<const Eigen::VectorXd>& dq,
                        const Eigen::Ref<const Eigen::VectorXd>& ddq,
                        Eigen::Ref<Eigen::MatrixXd> out);

}  // namespace dynid
