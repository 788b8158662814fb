#include "dynid/regressor/torque_regressor.hpp"

#include <cassert>

#include "dynamics/joint_pose.hpp"
#include "regressor/joint_columns.hpp"
#include "regressor/wrench_kernel.hpp"

namespace dynid {

void torque_regressor(const Model& model, Workspace& ws, const ParameterLayout& layout,
                      const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& ddq, Eigen::Ref<Eigen::MatrixXd> Y) {
  const int n = model.dof();
  assert(Y.rows() == n && Y.cols() == layout.columns(n));
  detail::local_kinematics(model, ws, q, dq, ddq, true);
  Y.setZero();
  detail::WrenchBlocks b;
  for (int j = 0; j < n; ++j) {
    const LinkState& s = ws.links[j];
    // Twists of joint j and its ancestors, carried into frame j: S_i^(j) = X_j·S_i^(parent).
    auto& twists = ws.twists[j];
    twists[0] = detail::joint_twist(model.joints[j]);
    if (model.joints[j].parent >= 0) {
      const auto& parent_twists = ws.twists[model.joints[j].parent];
      const Eigen::Matrix3d Rt = s.R_PJ.transpose();
      for (size_t k = 0; k < parent_twists.size(); ++k) {
        const auto& Sp = parent_twists[k];
        twists[k + 1].head<3>().noalias() = Rt * Sp.head<3>();
        twists[k + 1].tail<3>().noalias() = Rt * (Sp.tail<3>() + Sp.head<3>().cross(s.p_PJ));
      }
    }
    // Link j's wrench about its origin is linear in its parameters (seed 1 eq. 28); joint i's
    // torque is the power pairing of its twist with that wrench: tau_i += ω_iᵀ n_j + v_iᵀ f_j.
    detail::wrench_blocks(s.w, s.dw, s.a, b);
    for (size_t k = 0; k < twists.size(); ++k) {
      const int i = ws.ancestors[j][k];
      const Eigen::Vector3d w_i = twists[k].head<3>();
      const Eigen::Vector3d v_i = twists[k].tail<3>();
      auto row = Y.row(i).segment<kLinkParams>(kLinkParams * j);
      row.head<6>().noalias() = w_i.transpose() * b.L_I;
      row.segment<3>(6).noalias() = w_i.transpose() * b.A_skew + v_i.transpose() * b.K_mc;
      row(9) = v_i.dot(b.a);
    }
  }
  const int jc = layout.joint_columns();
  if (jc == 0) return;
  for (int j = 0; j < n; ++j) {
    detail::joint_columns(layout, dq[j], ddq[j], Y.row(j).segment(kLinkParams * n + jc * j, jc));
  }
}

}  // namespace dynid
