#include "dynid/dynamics/mass_matrix.hpp"

#include <cassert>

#include "dynamics/joint_pose.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/dynamics/rnea.hpp"

namespace dynid {

namespace {

// Composite-rigid-body algorithm (Featherstone 2008, Table 6.2) on the poses already in ws.links
// (R_PJ, p_PJ). Inertias stay as (I, h, m) at the link origins, and a subtree's inertia moves to
// the parent frame in closed form (docs/methods.md, "Mass matrix") instead of the 6×6 product
// Xᵀ·I·X; a joint's column is a force carried up the ancestor chain by one rotation and one cross
// product per ancestor. Writes the lower and upper triangles of M.
void composite_rigid_body(const Model& model, Workspace& ws, Eigen::Ref<Eigen::MatrixXd> M) {
  const int n = model.dof();
  for (int j = 0; j < n; ++j) {
    const LinkParams& p = model.links[j];
    BodyInertia& c = ws.composite[j];
    c.I = inertia_about_origin(p);
    c.h = p.segment<3>(6);
    c.m = p(9);
  }
  for (int j = n - 1; j >= 0; --j) {
    const int parent = model.joints[j].parent;
    if (parent < 0) continue;
    const BodyInertia& c = ws.composite[j];
    const Eigen::Matrix3d& R = ws.links[j].R_PJ;
    const Eigen::Vector3d& p = ws.links[j].p_PJ;
    // I_P = R·I·Rᵀ + 2(p·u)·1 − (u·pᵀ + p·uᵀ) with u = R·h + m·p/2 (parallel axes, both origins).
    const Eigen::Vector3d hR = R * c.h;
    const Eigen::Vector3d u = hR + 0.5 * c.m * p;
    const Eigen::Matrix3d RI = R * c.I;
    BodyInertia& cp = ws.composite[parent];
    cp.I.noalias() += RI * R.transpose();
    cp.I.noalias() -= u * p.transpose() + p * u.transpose();
    cp.I.diagonal().array() += 2.0 * p.dot(u);
    cp.h += hR + c.m * p;
    cp.m += c.m;
  }
  for (int i = 0; i < n; ++i) {
    const Joint& joint = model.joints[i];
    const BodyInertia& c = ws.composite[i];
    // Force (moment about origin i; force) = I^c_i·S_i for the unit twist S_i of joint i.
    Eigen::Vector3d nm, f;
    if (joint.type == JointType::kRevolute) {
      nm.noalias() = c.I * joint.axis;
      f = joint.axis.cross(c.h);
      M(i, i) = joint.axis.dot(nm) + joint.friction.Ia;
    } else {
      nm = c.h.cross(joint.axis);
      f = c.m * joint.axis;
      M(i, i) = joint.axis.dot(f) + joint.friction.Ia;
    }
    for (int j = i; model.joints[j].parent >= 0;) {
      const LinkState& s = ws.links[j];
      f = s.R_PJ * f;
      nm = s.R_PJ * nm + s.p_PJ.cross(f);
      j = model.joints[j].parent;
      const Joint& aj = model.joints[j];
      M(i, j) = M(j, i) = aj.axis.dot(aj.type == JointType::kRevolute ? nm : f);
    }
  }
}

}  // namespace

void mass_matrix(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                 Eigen::Ref<Eigen::MatrixXd> M) {
  const int n = model.dof();
  assert(M.rows() == n && M.cols() == n);
  for (int j = 0; j < n; ++j) detail::joint_pose(model.joints[j], q[j], ws.links[j]);
  M.setZero();
  composite_rigid_body(model, ws, M);
}

void forward_dynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> ddq,
                      const RneaOptions& options) {
  const int n = model.dof();
  ws.scratch_n2.setZero();
  // Bias c + g + friction at ddq = 0; it leaves the poses of q in ws.links for the CRBA.
  rnea(model, ws, q, dq, ws.scratch_n2, ws.scratch_n, options);
  Eigen::MatrixXd& H = ws.scratch_nn;
  composite_rigid_body(model, ws, H);
  // H = Lᵀ·D·L in place, L unit lower triangular with the tree's sparsity: L(k, i) ≠ 0 only for
  // ancestors i of k, so no fill-in (Featherstone 2008, Table 6.3, "LTDL"). Only the entries at
  // (k, ancestor of k) are read or written, which is why H need not be cleared.
  for (int k = n - 1; k >= 0; --k) {
    for (int i = model.joints[k].parent; i >= 0; i = model.joints[i].parent) {
      const double a = H(k, i) / H(k, k);
      for (int j = i; j >= 0; j = model.joints[j].parent) H(i, j) -= a * H(k, j);
      H(k, i) = a;
    }
  }
  // Lᵀ·D·L·ddq = tau − bias: back-substitute through Lᵀ, divide by D, forward through L
  // (Table 6.4).
  ddq = tau - ws.scratch_n;
  for (int i = n - 1; i >= 0; --i) {
    for (int j = model.joints[i].parent; j >= 0; j = model.joints[j].parent) {
      ddq[j] -= H(i, j) * ddq[i];
    }
  }
  for (int i = 0; i < n; ++i) ddq[i] /= H(i, i);
  for (int i = 0; i < n; ++i) {
    for (int j = model.joints[i].parent; j >= 0; j = model.joints[j].parent) {
      ddq[i] -= H(i, j) * ddq[j];
    }
  }
}

}  // namespace dynid
