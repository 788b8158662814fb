#include "dynid/dynamics/kinematics.hpp"

#include <Eigen/Geometry>

namespace dynid {

namespace {

// Pose of frame j in its parent at joint value qj: (R_PJ, p_PJ)·motion(axis, qj).
void joint_pose(const Joint& joint, double qj, LinkState& s) {
  if (joint.type == JointType::kRevolute) {
    s.R_PJ.noalias() = joint.R_PJ * Eigen::AngleAxisd(qj, joint.axis).toRotationMatrix();
    s.p_PJ = joint.p_PJ;
  } else {
    s.R_PJ = joint.R_PJ;
    s.p_PJ.noalias() = joint.p_PJ + joint.R_PJ * (joint.axis * qj);
  }
}

}  // namespace

void forward_kinematics(const Model& model, Workspace& ws,
                        const Eigen::Ref<const Eigen::VectorXd>& q) {
  for (int j = 0; j < model.dof(); ++j) {
    LinkState& s = ws.links[j];
    joint_pose(model.joints[j], q[j], s);
    const int p = model.joints[j].parent;
    if (p < 0) {
      s.R_WJ = s.R_PJ;
      s.p_WJ = s.p_PJ;
    } else {
      const LinkState& sp = ws.links[p];
      s.R_WJ.noalias() = sp.R_WJ * s.R_PJ;
      s.p_WJ.noalias() = sp.p_WJ + sp.R_WJ * s.p_PJ;
    }
  }
}

void forward_kinematics(const Model& model, Workspace& ws,
                        const Eigen::Ref<const Eigen::VectorXd>& q,
                        const Eigen::Ref<const Eigen::VectorXd>& dq,
                        const Eigen::Ref<const Eigen::VectorXd>& ddq, bool with_gravity) {
  forward_kinematics(model, ws, q);
  const Eigen::Vector3d a0 =
      with_gravity ? Eigen::Vector3d(-model.gravity) : Eigen::Vector3d::Zero();
  for (int j = 0; j < model.dof(); ++j) {
    const Joint& joint = model.joints[j];
    LinkState& s = ws.links[j];
    const Eigen::Matrix3d Rt = s.R_PJ.transpose();
    Eigen::Vector3d w_in, v_in, dw_in, a_in;  // parent quantities carried into frame j
    if (joint.parent < 0) {
      w_in.setZero();
      v_in.setZero();
      dw_in.setZero();
      a_in.noalias() = Rt * a0;
    } else {
      const LinkState& sp = ws.links[joint.parent];
      w_in.noalias() = Rt * sp.w;
      v_in.noalias() = Rt * (sp.v + sp.w.cross(s.p_PJ));
      dw_in.noalias() = Rt * sp.dw;
      a_in.noalias() = Rt * (sp.a + sp.dw.cross(s.p_PJ) + sp.w.cross(sp.w.cross(s.p_PJ)));
    }
    const Eigen::Vector3d z_dq = joint.axis * dq[j];
    const Eigen::Vector3d z_ddq = joint.axis * ddq[j];
    if (joint.type == JointType::kRevolute) {
      s.w = w_in + z_dq;
      s.v = v_in;
      s.dw = dw_in + w_in.cross(z_dq) + z_ddq;
      s.a = a_in;
    } else {
      s.w = w_in;
      s.v = v_in + z_dq;
      s.dw = dw_in;
      s.a = a_in + 2.0 * w_in.cross(z_dq) + z_ddq;
    }
  }
}

}  // namespace dynid
