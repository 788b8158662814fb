#include "dynid/regressor/energy_regressor.hpp"

#include <cassert>

#include "dynid/dynamics/kinematics.hpp"
#include "regressor/friction_work.hpp"

namespace dynid {

void energy_regressor(const Model& model, Workspace& ws, const ParameterLayout& layout,
                      const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq, Eigen::Ref<Eigen::VectorXd> h) {
  const int n = model.dof();
  assert(h.size() == layout.columns(n));
  ws.scratch_n.setZero();
  forward_kinematics(model, ws, q, dq, ws.scratch_n, false);
  h.setZero();
  for (int j = 0; j < n; ++j) {
    // H = E_k + E_p linear in the standard parameters (seed 1 eqs. 6, 7, 12; seed 2 eqs. 4–5):
    // ½ωᵀI_Oω + mc·(v×ω − R_WJᵀg) + m(½v·v − g·p_WJ).
    const LinkState& s = ws.links[j];
    const Eigen::Vector3d& w = s.w;
    auto hj = h.segment<kLinkParams>(kLinkParams * j);
    hj << 0.5 * w.x() * w.x(), w.x() * w.y(), w.x() * w.z(), 0.5 * w.y() * w.y(), w.y() * w.z(),
        0.5 * w.z() * w.z(), 0, 0, 0, 0.5 * s.v.squaredNorm() - model.gravity.dot(s.p_WJ);
    hj.segment<3>(6) = s.v.cross(w) - s.R_WJ.transpose() * model.gravity;
  }
  if (layout.armature) {
    const int jc = layout.joint_columns();
    for (int j = 0; j < n; ++j) h[kLinkParams * n + jc * j] = 0.5 * dq[j] * dq[j];
  }
}

void integral_regressor(const Model& model, Workspace& ws, const ParameterLayout& layout,
                        const Eigen::Ref<const Eigen::VectorXd>& t,
                        const Eigen::Ref<const Eigen::MatrixXd>& q,
                        const Eigen::Ref<const Eigen::MatrixXd>& dq,
                        const Eigen::Ref<const Eigen::MatrixXd>& tau, double& y,
                        Eigen::Ref<Eigen::VectorXd> d) {
  const int n = model.dof();
  const Eigen::Index m = t.size();
  assert(m >= 2 && q.rows() == m && dq.rows() == m && tau.rows() == m && q.cols() == n);
  const int jc = layout.joint_columns();
  const int p = layout.columns(n);
  // Seed 1 eq. 10–11: the conservative part is H(t2) − H(t1).
  energy_regressor(model, ws, layout, q.row(m - 1).transpose(), dq.row(m - 1).transpose(), d);
  Eigen::VectorXd h_begin(p);
  energy_regressor(model, ws, layout, q.row(0).transpose(), dq.row(0).transpose(), h_begin);
  d -= h_begin;
  // Seed 1 eqs. 15–17: friction work per step from the quadratic velocity through the step's
  // end velocities and position change (exact for cubic q, split at reversals); armature is in
  // H already. y = ∫ tauᵀ dq dt by the trapezoidal rule.
  y = 0.0;
  for (Eigen::Index k = 0; k + 1 < m; ++k) {
    const double dt = t[k + 1] - t[k];
    y += 0.5 * dt * (tau.row(k).dot(dq.row(k)) + tau.row(k + 1).dot(dq.row(k + 1)));
    for (int j = 0; j < n; ++j) {
      detail::add_friction_work(
          layout, step_velocity_integrals(dt, q(k + 1, j) - q(k, j), dq(k, j), dq(k + 1, j)),
          d.segment(kLinkParams * n + jc * j, jc));
    }
  }
}

}  // namespace dynid
