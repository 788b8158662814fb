#include "dynid/dynamics/mass_matrix.hpp"

#include <cassert>

#include "dynamics/spatial.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/dynamics/rnea.hpp"

namespace dynid {

void mass_matrix(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                 Eigen::Ref<Eigen::MatrixXd> M) {
  using detail::Matrix6d;
  using detail::Vector6d;
  const int n = model.dof();
  assert(M.rows() == n && M.cols() == n);
  forward_kinematics(model, ws, q);
  for (int j = 0; j < n; ++j) ws.composite[j] = detail::spatial_inertia(model.links[j]);
  // Composite-rigid-body algorithm (Featherstone 2008, Table 6.2), spatial quantities at the link
  // origins in link frames.
  for (int j = n - 1; j >= 0; --j) {
    const int p = model.joints[j].parent;
    if (p >= 0) {
      const Matrix6d X = detail::motion_transform(ws.links[j].R_PJ, ws.links[j].p_PJ);
      ws.composite[p].noalias() += X.transpose() * ws.composite[j] * X;
    }
  }
  M.setZero();
  for (int i = 0; i < n; ++i) {
    Vector6d F = ws.composite[i] * detail::joint_twist(model.joints[i]);
    M(i, i) = detail::joint_twist(model.joints[i]).dot(F) + model.joints[i].friction.Ia;
    int j = i;
    while (model.joints[j].parent >= 0) {
      F = detail::motion_transform(ws.links[j].R_PJ, ws.links[j].p_PJ).transpose() * F;
      j = model.joints[j].parent;
      M(i, j) = M(j, i) = detail::joint_twist(model.joints[j]).dot(F);
    }
  }
}

void forward_dynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> ddq,
                      const RneaOptions& options) {
  ws.scratch_n2.setZero();
  rnea(model, ws, q, dq, ws.scratch_n2, ws.scratch_n, options);  // bias c + g + friction at ddq = 0
  mass_matrix(model, ws, q, ws.scratch_nn);
  ws.llt.compute(ws.scratch_nn);
  ddq = tau - ws.scratch_n;
  ws.llt.solveInPlace(ddq);
}

}  // namespace dynid
