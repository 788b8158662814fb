#include "dynid/dynamics/energy.hpp"

#include "dynid/dynamics/kinematics.hpp"

namespace dynid {

double kinetic_energy(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq) {
  ws.scratch_n.setZero();
  forward_kinematics(model, ws, q, dq, ws.scratch_n, false);
  double e = 0.0;
  for (int j = 0; j < model.dof(); ++j) {
    // E_k = ½ m v·v + mc·(v × ω) + ½ ωᵀ I_O ω about the link origin (seed 1 eq. 6).
    const LinkState& s = ws.links[j];
    const LinkParams& p = model.links[j];
    e += 0.5 * p(9) * s.v.squaredNorm() + p.segment<3>(6).dot(s.v.cross(s.w)) +
         0.5 * s.w.dot(inertia_about_origin(p) * s.w) +
         0.5 * model.joints[j].friction.Ia * dq[j] * dq[j];
  }
  return e;
}

double potential_energy(const Model& model, Workspace& ws,
                        const Eigen::Ref<const Eigen::VectorXd>& q) {
  forward_kinematics(model, ws, q);
  double e = 0.0;
  for (int j = 0; j < model.dof(); ++j) {
    const LinkState& s = ws.links[j];
    const LinkParams& p = model.links[j];
    e -= model.gravity.dot(p(9) * s.p_WJ + s.R_WJ * p.segment<3>(6));
  }
  return e;
}

}  // namespace dynid
