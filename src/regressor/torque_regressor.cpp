#include "dynid/regressor/torque_regressor.hpp"

#include <algorithm>
#include <cassert>

#include "dynamics/joint_pose.hpp"
#include "regressor/joint_columns.hpp"
#include "regressor/wrench_kernel.hpp"

namespace dynid {

namespace {

// One (joint i, link j) block of the regressor: the power pairing of joint i's unit twist
// (w; v), expressed in frame j, with link j's parameter-linear wrench (seed 1 eq. 28):
// tau_i += ωᵀn_j + vᵀf_j. The ten entries go to out[0], out[ld], … (a row of Y).
inline void pair_block(const Eigen::Vector3d& w, const Eigen::Vector3d& v,
                       const detail::WrenchBlocks& b, double* out, Eigen::Index ld) {
  // ωᵀL_I, with L_I = [·dω] + [ω×][·ω] kept as its 3×6 matrix.
  for (int c = 0; c < 6; ++c) {
    out[c * ld] = w.x() * b.L_I(0, c) + w.y() * b.L_I(1, c) + w.z() * b.L_I(2, c);
  }
  // ωᵀ(−[a×]) = (a × ω)ᵀ, plus vᵀK_mc.
  const Eigen::Vector3d m = b.a.cross(w) + b.K_mc.transpose() * v;
  out[6 * ld] = m.x();
  out[7 * ld] = m.y();
  out[8 * ld] = m.z();
  out[9 * ld] = v.dot(b.a);
}

}  // namespace

void torque_regressor(const Model& model, Workspace& ws, const ParameterLayout& layout,
                      const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& ddq, Eigen::Ref<Eigen::MatrixXd> Y) {
  const int n = model.dof();
  assert(Y.rows() == n && Y.cols() == layout.columns(n));
  detail::local_kinematics(model, ws, q, dq, ddq, true);
  double* const y = Y.data();
  const Eigen::Index ld = Y.outerStride();
  // A contiguous Y is cleared by one fill: Eigen's setZero on a Ref clears it column by column
  // (a 56-byte memset call per column for 7 joints: 7 % of a streaming identification's CPU time).
  if (ld == n) {
    std::fill(y, y + n * Y.cols(), 0.0);
  } else {
    Y.setZero();
  }
  detail::WrenchBlocks b;
  for (int j = 0; j < n; ++j) {
    const LinkState& s = ws.links[j];
    const Joint& joint = model.joints[j];
    detail::wrench_blocks(s.w, s.dw, s.a, b);
    double* const block = y + ld * kLinkParams * j;  // column 10j of Y
    // Joint j's own row: its twist is the joint axis in frame j, (axis; 0) or (0; axis).
    auto& twists = ws.twists[j];
    twists[0] = detail::joint_twist(joint);
    pair_block(twists[0].head<3>(), twists[0].tail<3>(), b, block + j, ld);
    if (joint.parent < 0) continue;
    // The ancestors' twists, carried from the parent's frame into frame j:
    // ω' = Rᵀω, v' = Rᵀ(v + ω × p), then paired with link j's wrench at once.
    const auto& parent_twists = ws.twists[joint.parent];
    const Eigen::Matrix3d Rt = s.R_PJ.transpose();
    const std::vector<int>& anc = ws.ancestors[j];
    for (std::size_t k = 0; k < parent_twists.size(); ++k) {
      const auto& Sp = parent_twists[k];
      const Eigen::Vector3d wp = Sp.head<3>();
      const Eigen::Vector3d w_i = Rt * wp;
      const Eigen::Vector3d v_i = Rt * (Sp.tail<3>() + wp.cross(s.p_PJ));
      twists[k + 1].head<3>() = w_i;
      twists[k + 1].tail<3>() = v_i;
      pair_block(w_i, v_i, b, block + anc[k + 1], ld);
    }
  }
  const int jc = layout.joint_columns();
  if (jc == 0) return;
  for (int j = 0; j < n; ++j) {
    detail::joint_columns(layout, dq[j], ddq[j], Y.row(j).segment(kLinkParams * n + jc * j, jc));
  }
}

}  // namespace dynid
