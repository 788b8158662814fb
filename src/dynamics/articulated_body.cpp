#include "dynid/dynamics/articulated_body.hpp"

#include <cassert>

#include "dynamics/joint_pose.hpp"
#include "dynamics/joint_terms.hpp"

namespace dynid {

namespace {

// Adds Xᵀ·[[A, B], [Bᵀ, C]]·X to the parent's blocks, X the motion transform from the parent to
// frame j (pose (R, p) of j in the parent): rotate every block, R·A·Rᵀ, R·B·Rᵀ, R·C·Rᵀ, then
// shift the reference point by p with P = [p×]: A += P·Bᵀ + B·Pᵀ − P·C·P, B += P·C
// (docs/methods/dynamics.md, "Articulated-body algorithm").
inline void add_inertia_to_parent(const Eigen::Matrix3d& R, const Eigen::Vector3d& p,
                                  const Eigen::Matrix3d& A, const Eigen::Matrix3d& B,
                                  const Eigen::Matrix3d& C, ArticulatedBody& parent) {
  const Eigen::Matrix3d Ar = R * A * R.transpose();
  const Eigen::Matrix3d Br = R * B * R.transpose();
  const Eigen::Matrix3d Cr = R * C * R.transpose();
  // Products with P as column-wise cross products: 18 products each instead of 27.
  Eigen::Matrix3d PC, PBt, PCPt;
  for (int k = 0; k < 3; ++k) {
    PC.col(k) = p.cross(Cr.col(k));
    PBt.col(k) = p.cross(Br.row(k).transpose());
  }
  // −P·C·P = P·C·Pᵀ = P·(P·C)ᵀ, C being symmetric.
  for (int k = 0; k < 3; ++k) PCPt.col(k) = p.cross(PC.row(k).transpose());
  parent.A += Ar + PBt + PBt.transpose() + PCPt;
  parent.B += Br + PC;
  parent.C += Cr;
}

}  // namespace

void articulated_body_forward_dynamics(const Model& model, Workspace& ws,
                                       const Eigen::Ref<const Eigen::VectorXd>& q,
                                       const Eigen::Ref<const Eigen::VectorXd>& dq,
                                       const Eigen::Ref<const Eigen::VectorXd>& tau,
                                       Eigen::Ref<Eigen::VectorXd> ddq,
                                       const RneaOptions& options) {
  const int n = model.dof();
  assert(q.size() == n && dq.size() == n && tau.size() == n && ddq.size() == n);
  // Pass 1 (parents first): poses, velocities, the velocity-product accelerations c_j = v_j ×
  // S_j·q̇_j and each link's own inertia and bias force v ×* I·v (Table 7.1, first loop).
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joints[j];
    LinkState& s = ws.links[j];
    ArticulatedBody& b = ws.articulated[j];
    detail::joint_pose(joint, q[j], s);
    Eigen::Vector3d w_in = Eigen::Vector3d::Zero(), v_in = Eigen::Vector3d::Zero();
    if (joint.parent >= 0) {
      const LinkState& sp = ws.links[joint.parent];
      w_in.noalias() = s.R_PJ.transpose() * sp.w;
      v_in.noalias() = s.R_PJ.transpose() * (sp.v + sp.w.cross(s.p_PJ));
    }
    const Eigen::Vector3d sdq = joint.axis * dq[j];
    if (joint.type == JointType::kRevolute) {
      s.w = w_in + sdq;
      s.v = v_in;
      b.c_w = w_in.cross(sdq);
      b.c_v = v_in.cross(sdq);
    } else {
      s.w = w_in;
      s.v = v_in + sdq;
      b.c_w.setZero();
      b.c_v = w_in.cross(sdq);
    }
    const LinkParams& p = model.links[j];
    const Eigen::Vector3d h = p.segment<3>(6);
    b.A << p(0), p(1), p(2), p(1), p(3), p(4), p(2), p(4), p(5);
    b.B << 0.0, -h.z(), h.y(), h.z(), 0.0, -h.x(), -h.y(), h.x(), 0.0;
    b.C = p(9) * Eigen::Matrix3d::Identity();
    // Momentum (I·ω + h × v; m·v − h × ω), then the bias force v ×* momentum.
    const Eigen::Vector3d mom_n = b.A * s.w + h.cross(s.v);
    const Eigen::Vector3d mom_f = p(9) * s.v - h.cross(s.w);
    b.p_n = s.w.cross(mom_n) + s.v.cross(mom_f);
    b.p_f = s.w.cross(mom_f);
  }
  // Pass 2 (children first): U = I^A·S, D = Sᵀ·U + Ia, u = τ − Sᵀ·p^A − friction, and the
  // articulated inertia I^A − U·Uᵀ/D and bias p^A + I^a·c + U·u/D handed to the parent.
  for (int j = n - 1; j >= 0; --j) {
    const Joint& joint = model.joints[j];
    ArticulatedBody& b = ws.articulated[j];
    const Eigen::Vector3d& ax = joint.axis;
    const bool revolute = joint.type == JointType::kRevolute;
    if (revolute) {
      b.U_n.noalias() = b.A * ax;
      b.U_f.noalias() = b.B.transpose() * ax;
      b.D = ax.dot(b.U_n);
      b.u = tau[j] - ax.dot(b.p_n);
    } else {
      b.U_n.noalias() = b.B * ax;
      b.U_f.noalias() = b.C * ax;
      b.D = ax.dot(b.U_f);
      b.u = tau[j] - ax.dot(b.p_f);
    }
    b.D += joint.friction.Ia;
    if (options.joint_terms) b.u -= detail::joint_torque(joint.friction, dq[j], 0.0);
    if (joint.parent < 0) continue;
    const double inv_d = 1.0 / b.D;
    const Eigen::Vector3d Un_d = inv_d * b.U_n, Uf_d = inv_d * b.U_f;
    const Eigen::Matrix3d A = b.A - Un_d * b.U_n.transpose();
    const Eigen::Matrix3d B = b.B - Un_d * b.U_f.transpose();
    const Eigen::Matrix3d C = b.C - Uf_d * b.U_f.transpose();
    const Eigen::Vector3d pa_n = b.p_n + A * b.c_w + B * b.c_v + b.u * Un_d;
    const Eigen::Vector3d pa_f = b.p_f + B.transpose() * b.c_w + C * b.c_v + b.u * Uf_d;
    const LinkState& s = ws.links[j];
    ArticulatedBody& bp = ws.articulated[joint.parent];
    add_inertia_to_parent(s.R_PJ, s.p_PJ, A, B, C, bp);
    const Eigen::Vector3d f = s.R_PJ * pa_f;
    bp.p_n += s.R_PJ * pa_n + s.p_PJ.cross(f);
    bp.p_f += f;
  }
  // Pass 3 (parents first): a' = X·a_parent + c, q̈ = (u − Uᵀ·a')/D, a = a' + S·q̈. The base
  // accelerates by −g (gravity trick, as the RNEA).
  const Eigen::Vector3d a0 =
      options.gravity ? Eigen::Vector3d(-model.gravity) : Eigen::Vector3d::Zero();
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joints[j];
    const LinkState& s = ws.links[j];
    ArticulatedBody& b = ws.articulated[j];
    if (joint.parent < 0) {
      b.a_w = b.c_w;
      b.a_v.noalias() = s.R_PJ.transpose() * a0;
      b.a_v += b.c_v;
    } else {
      const ArticulatedBody& bp = ws.articulated[joint.parent];
      b.a_w.noalias() = s.R_PJ.transpose() * bp.a_w;
      b.a_w += b.c_w;
      b.a_v.noalias() = s.R_PJ.transpose() * (bp.a_v + bp.a_w.cross(s.p_PJ));
      b.a_v += b.c_v;
    }
    ddq[j] = (b.u - b.U_n.dot(b.a_w) - b.U_f.dot(b.a_v)) / b.D;
    if (joint.type == JointType::kRevolute) {
      b.a_w += ddq[j] * joint.axis;
    } else {
      b.a_v += ddq[j] * joint.axis;
    }
  }
}

}  // namespace dynid
