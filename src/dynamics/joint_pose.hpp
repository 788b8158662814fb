#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "dynid/dynamics/workspace.hpp"

namespace dynid::detail {

/// Pose of frame j in its parent at joint value qj: (R_PJ, p_PJ)·motion(axis, qj), written into
/// s.R_PJ and s.p_PJ. A revolute joint about ±z (most URDF and MDH joints) rotates two columns of
/// R_PJ (12 products) instead of building the axis-angle matrix and multiplying (27 + Rodrigues).
inline void joint_pose(const Joint& joint, double qj, LinkState& s) {
  if (joint.type == JointType::kRevolute) {
    s.p_PJ = joint.p_PJ;
    if (joint.axis.x() == 0.0 && joint.axis.y() == 0.0) {
      const double c = std::cos(qj), sn = joint.axis.z() * std::sin(qj);
      s.R_PJ.col(0) = c * joint.R_PJ.col(0) + sn * joint.R_PJ.col(1);
      s.R_PJ.col(1) = c * joint.R_PJ.col(1) - sn * joint.R_PJ.col(0);
      s.R_PJ.col(2) = joint.R_PJ.col(2);
    } else {
      s.R_PJ.noalias() = joint.R_PJ * Eigen::AngleAxisd(qj, joint.axis).toRotationMatrix();
    }
  } else {
    s.R_PJ = joint.R_PJ;
    s.p_PJ.noalias() = joint.p_PJ + joint.R_PJ * (joint.axis * qj);
  }
}

/// forward_kinematics(model, ws, q, dq, ddq, with_gravity) without the base-frame poses R_WJ,
/// p_WJ, which the RNEA and the torque regressor do not use: fills R_PJ, p_PJ, w, v, dw, a.
void local_kinematics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& ddq, bool with_gravity);

}  // namespace dynid::detail
