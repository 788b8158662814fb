#include "dynid/dynamics/rnea.hpp"

#include <cassert>

#include "dynamics/joint_pose.hpp"
#include "dynamics/joint_terms.hpp"

namespace dynid {

void rnea(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
          const Eigen::Ref<const Eigen::VectorXd>& dq, const Eigen::Ref<const Eigen::VectorXd>& ddq,
          Eigen::Ref<Eigen::VectorXd> tau, const RneaOptions& options) {
  const int n = model.dof();
  assert(q.size() == n && dq.size() == n && ddq.size() == n && tau.size() == n);
  detail::local_kinematics(model, ws, q, dq, ddq, options.gravity);
  for (int j = 0; j < n; ++j) {
    // Newton–Euler equations of link j about its origin (Khalil–Dombre eq. 9.88–9.89).
    LinkState& s = ws.links[j];
    const LinkParams& p = model.links[j];
    const Eigen::Vector3d mc = p.segment<3>(6);
    const Eigen::Matrix3d I = inertia_about_origin(p);
    s.f = p(9) * s.a + s.dw.cross(mc) + s.w.cross(s.w.cross(mc));
    s.n = I * s.dw + s.w.cross(I * s.w) + mc.cross(s.a);
  }
  for (int j = n - 1; j >= 0; --j) {
    const Joint& joint = model.joints[j];
    const LinkState& s = ws.links[j];
    tau[j] = joint.type == JointType::kRevolute ? joint.axis.dot(s.n) : joint.axis.dot(s.f);
    if (options.joint_terms) tau[j] += detail::joint_torque(joint.friction, dq[j], ddq[j]);
    if (joint.parent >= 0) {
      LinkState& sp = ws.links[joint.parent];
      const Eigen::Vector3d f_P = s.R_PJ * s.f;
      sp.f += f_P;
      sp.n += s.R_PJ * s.n + s.p_PJ.cross(f_P);
    }
  }
}

Eigen::VectorXd rnea(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& dq,
                     const Eigen::VectorXd& ddq, const RneaOptions& options) {
  Workspace ws(model);
  Eigen::VectorXd tau(model.dof());
  rnea(model, ws, q, dq, ddq, tau, options);
  return tau;
}

}  // namespace dynid
