#include "dynid/dynamics/kinematics.hpp"

#include "dynamics/joint_pose.hpp"

namespace dynid {

namespace {

// Velocities and accelerations of every link from the local poses already in ws.links.
void motion(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& dq,
            const Eigen::Ref<const Eigen::VectorXd>& ddq, bool with_gravity) {
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

}  // namespace

void forward_kinematics(const Model& model, Workspace& ws,
                        const Eigen::Ref<const Eigen::VectorXd>& q) {
  for (int j = 0; j < model.dof(); ++j) {
    LinkState& s = ws.links[j];
    detail::joint_pose(model.joints[j], q[j], s);
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
  motion(model, ws, dq, ddq, with_gravity);
}

void detail::local_kinematics(const Model& model, Workspace& ws,
                              const Eigen::Ref<const Eigen::VectorXd>& q,
                              const Eigen::Ref<const Eigen::VectorXd>& dq,
                              const Eigen::Ref<const Eigen::VectorXd>& ddq, bool with_gravity) {
  for (int j = 0; j < model.dof(); ++j) detail::joint_pose(model.joints[j], q[j], ws.links[j]);
  motion(model, ws, dq, ddq, with_gravity);
}

}  // namespace dynid
