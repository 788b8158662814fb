#include "dynid/dynamics/mass_matrix.hpp"

#include <cassert>

#include "dynamics/body_inertia.hpp"
#include "dynamics/joint_pose.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/dynamics/rnea.hpp"

namespace dynid {

namespace {

// The six force components (moment about origin j; force) of the columns, one array each.
struct ColumnForces {
  double* n0;
  double* n1;
  double* n2;
  double* f0;
  double* f1;
  double* f2;
};

// f ← R·f, n ← R·n + p × f for one column (T = double) or two side by side (T = Array2d).
// Always inlined: GCC kept the Array2d version out of line, re-broadcasting R and p at every call
// (the mass matrix took 5–7 % longer).
template <typename T>
EIGEN_ALWAYS_INLINE void carry(const Eigen::Matrix3d& R, const Eigen::Vector3d& p, T& n0, T& n1,
                               T& n2, T& f0, T& f1, T& f2) {
  const T g0 = R(0, 0) * f0 + R(0, 1) * f1 + R(0, 2) * f2;
  const T g1 = R(1, 0) * f0 + R(1, 1) * f1 + R(1, 2) * f2;
  const T g2 = R(2, 0) * f0 + R(2, 1) * f1 + R(2, 2) * f2;
  const T m0 = R(0, 0) * n0 + R(0, 1) * n1 + R(0, 2) * n2 + (p[1] * g2 - p[2] * g1);
  const T m1 = R(1, 0) * n0 + R(1, 1) * n1 + R(1, 2) * n2 + (p[2] * g0 - p[0] * g2);
  const T m2 = R(2, 0) * n0 + R(2, 1) * n1 + R(2, 2) * n2 + (p[0] * g1 - p[1] * g0);
  n0 = m0;
  n1 = m1;
  n2 = m2;
  f0 = g0;
  f1 = g1;
  f2 = g2;
}

// Carries the forces of columns [begin, end) from frame j to its parent (moment about the
// parent's origin), two columns per SIMD operation.
inline void forces_to_parent(const Eigen::Matrix3d& R, const Eigen::Vector3d& p,
                             const ColumnForces& F, int begin, int end) {
  int k = begin;
  for (; k + 1 < end; k += 2) {
    using Pair = Eigen::Map<Eigen::Array2d>;
    Eigen::Array2d n0 = Pair(F.n0 + k), n1 = Pair(F.n1 + k), n2 = Pair(F.n2 + k);
    Eigen::Array2d f0 = Pair(F.f0 + k), f1 = Pair(F.f1 + k), f2 = Pair(F.f2 + k);
    carry(R, p, n0, n1, n2, f0, f1, f2);
    Pair(F.n0 + k) = n0;
    Pair(F.n1 + k) = n1;
    Pair(F.n2 + k) = n2;
    Pair(F.f0 + k) = f0;
    Pair(F.f1 + k) = f1;
    Pair(F.f2 + k) = f2;
  }
  if (k < end) carry(R, p, F.n0[k], F.n1[k], F.n2[k], F.f0[k], F.f1[k], F.f2[k]);
}

// Whether joint k lies in the subtree of joint j (k ≥ j; parents precede children).
inline bool in_subtree(const Model& model, int k, int j) {
  while (k > j) k = model.joints[k].parent;
  return k == j;
}

// Composite-rigid-body algorithm (Featherstone 2008, Table 6.2) on the poses already in ws.links
// (R_PJ, p_PJ), arranged as Pinocchio's CRBA: one backward pass in which joint j, once its
// composite inertia is complete, opens its column F_j = I^c_j·S_j, reads row j of M from the
// forces of its whole subtree (all expressed in frame j by then), and carries those forces and
// its composite inertia to the parent. The columns of a subtree are independent, so carrying them
// together is a loop without a dependency chain. Writes the entries (j, k) and (k, j) for k in the
// subtree of j; the others (different branches) are left as they were.
void composite_rigid_body(const Model& model, Workspace& ws, Eigen::Ref<Eigen::MatrixXd> M) {
  const int n = model.dof();
  for (int j = 0; j < n; ++j) {
    const LinkParams& p = model.links[j];
    BodyInertia& c = ws.composite[j];
    // inertia_about_origin(p) written out: the out-of-line call took 13 % of the mass matrix.
    c.I << p(0), p(1), p(2), p(1), p(3), p(4), p(2), p(4), p(5);
    c.h = p.segment<3>(6);
    c.m = p(9);
  }
  const ColumnForces F{ws.forces.col(0).data(), ws.forces.col(1).data(), ws.forces.col(2).data(),
                       ws.forces.col(3).data(), ws.forces.col(4).data(), ws.forces.col(5).data()};
  double* const n0 = F.n0;
  double* const n1 = F.n1;
  double* const n2 = F.n2;
  double* const f0 = F.f0;
  double* const f1 = F.f1;
  double* const f2 = F.f2;
  const bool depth_first = ws.depth_first;
  for (int j = n - 1; j >= 0; --j) {
    const Joint& joint = model.joints[j];
    const BodyInertia& c = ws.composite[j];
    const Eigen::Vector3d& a = joint.axis;
    const bool revolute = joint.type == JointType::kRevolute;
    // F_j = I^c_j·S_j: (I·a; a × h) for a revolute axis a, (h × a; m·a) for a prismatic one.
    if (revolute) {
      const Eigen::Vector3d Ia = c.I * a;
      n0[j] = Ia.x();
      n1[j] = Ia.y();
      n2[j] = Ia.z();
      f0[j] = a.y() * c.h.z() - a.z() * c.h.y();
      f1[j] = a.z() * c.h.x() - a.x() * c.h.z();
      f2[j] = a.x() * c.h.y() - a.y() * c.h.x();
    } else {
      n0[j] = c.h.y() * a.z() - c.h.z() * a.y();
      n1[j] = c.h.z() * a.x() - c.h.x() * a.z();
      n2[j] = c.h.x() * a.y() - c.h.y() * a.x();
      f0[j] = c.m * a.x();
      f1[j] = c.m * a.y();
      f2[j] = c.m * a.z();
    }
    // Row j: M(j, k) = S_jᵀ·F_k for k in the subtree of j. A root's children have written its
    // row for their subtrees already (below), which leaves its diagonal. Scalars in locals: M's
    // stores could alias the model's and workspace's doubles as far as the compiler knows.
    const int parent = joint.parent;
    const int end = ws.subtree_end[j];
    const double* const x = revolute ? n0 : f0;
    const double* const y = revolute ? n1 : f1;
    const double* const z = revolute ? n2 : f2;
    const double ax = a.x(), ay = a.y(), az = a.z();
    const int row_end = parent < 0 ? j + 1 : end;
    if (depth_first && ax == 0.0 && ay == 0.0) {
      // Axis ±z (every built-in robot): the same sum without its two zero terms.
      for (int k = j; k < row_end; ++k) M(k, j) = M(j, k) = az * z[k];
    } else {
      for (int k = j; k < row_end; ++k) {
        if (!depth_first && !in_subtree(model, k, j)) continue;
        M(k, j) = M(j, k) = ax * x[k] + ay * y[k] + az * z[k];
      }
    }
    M(j, j) += joint.friction.Ia;
    if (parent < 0) continue;
    const Eigen::Matrix3d& R = ws.links[j].R_PJ;
    const Eigen::Vector3d& pj = ws.links[j].p_PJ;
    const Joint& pjoint = model.joints[parent];
    if (pjoint.parent < 0) {
      // The parent is a root: its row is all the forces are still needed for, so pair them here
      // with its unit twist expressed in frame j, (ω; v) = (Rᵀa; Rᵀ(a × p)) revolute or
      // (0; Rᵀa) prismatic, 6 products per column instead of carrying (27).
      const Eigen::Vector3d Rta = R.transpose() * pjoint.axis;
      Eigen::Vector3d w = Eigen::Vector3d::Zero(), v = Rta;
      if (pjoint.type == JointType::kRevolute) {
        w = Rta;
        v.noalias() = R.transpose() * pjoint.axis.cross(pj);
      }
      const double w0 = w[0], w1 = w[1], w2 = w[2], v0 = v[0], v1 = v[1], v2 = v[2];
      for (int k = j; k < end; ++k) {
        if (!depth_first && !in_subtree(model, k, j)) continue;
        M(k, parent) = M(parent, k) =
            w0 * n0[k] + w1 * n1[k] + w2 * n2[k] + (v0 * f0[k] + v1 * f1[k] + v2 * f2[k]);
      }
    } else if (depth_first) {
      forces_to_parent(R, pj, F, j, end);
    } else {
      for (int k = j; k < end; ++k) {
        if (in_subtree(model, k, j)) forces_to_parent(R, pj, F, k, k + 1);
      }
    }
    detail::add_to_parent(R, pj, c, ws.composite[parent]);
  }
}

}  // namespace

void mass_matrix(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                 Eigen::Ref<Eigen::MatrixXd> M) {
  const int n = model.dof();
  assert(M.rows() == n && M.cols() == n);
  for (int j = 0; j < n; ++j) detail::joint_pose(model.joints[j], q[j], ws.links[j]);
  // Only a chain has every entry related by ancestry; elsewhere the branches' entries are zero.
  bool chain = true;
  for (int j = 0; j < n; ++j) chain = chain && model.joints[j].parent == j - 1;
  if (!chain) M.setZero();
  composite_rigid_body(model, ws, M);
}

void crba_forward_dynamics(const Model& model, Workspace& ws,
                           const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::VectorXd>& dq,
                           const Eigen::Ref<const Eigen::VectorXd>& tau,
                           Eigen::Ref<Eigen::VectorXd> ddq, const RneaOptions& options) {
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

bool prefers_articulated_body(const Workspace& ws) {
  const auto n = static_cast<long>(ws.links.size());
  return 2L * ws.depth_sum >= (kArticulatedBodyMinChain + 1L) * n;
}

void forward_dynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> ddq,
                      const RneaOptions& options) {
  if (prefers_articulated_body(ws)) {
    articulated_body_forward_dynamics(model, ws, q, dq, tau, ddq, options);
  } else {
    crba_forward_dynamics(model, ws, q, dq, tau, ddq, options);
  }
}

}  // namespace dynid
