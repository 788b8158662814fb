#include "dynid/dynamics/rnea_derivatives.hpp"

#include <cassert>

#include "dynamics/body_inertia.hpp"
#include "dynamics/joint_terms.hpp"
#include "dynid/dynamics/kinematics.hpp"

namespace dynid {

namespace {

using Eigen::Vector3d;

// Spatial algebra in (ω; v_O) / (n_O; f) pairs about the world origin (Featherstone 2008, ch. 2).

// Motion cross product m1 × m2.
inline void cross_motion(const Vector3d& w1, const Vector3d& v1, const Vector3d& w2,
                         const Vector3d& v2, Vector3d& out_w, Vector3d& out_v) {
  out_w = w1.cross(w2);
  out_v = w1.cross(v2) + v1.cross(w2);
}

// Force cross product m ×* f.
inline void cross_force(const Vector3d& w, const Vector3d& v, const Vector3d& n, const Vector3d& f,
                        Vector3d& out_n, Vector3d& out_f) {
  out_n = w.cross(n) + v.cross(f);
  out_f = w.cross(f);
}

// The force Y·m of the inertia (I, h, m) = [[I, [h×]], [−[h×], m·1]] acting on a motion (ω; v).
inline void inertia_action(const BodyInertia& Y, const Vector3d& w, const Vector3d& v, Vector3d& n,
                           Vector3d& f) {
  n.noalias() = Y.I * w;
  n += Y.h.cross(v);
  f = Y.m * v - Y.h.cross(w);
}

inline double dot(const Vector3d& w, const Vector3d& v, const Vector3d& n, const Vector3d& f) {
  return w.dot(n) + v.dot(f);
}

inline void add(const BodyInertia& c, BodyInertia& to) {
  to.I += c.I;
  to.h += c.h;
  to.m += c.m;
}

}  // namespace

void rnea_derivatives(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& ddq,
                      Eigen::Ref<Eigen::MatrixXd> partial_q, Eigen::Ref<Eigen::MatrixXd> partial_dq,
                      Eigen::Ref<Eigen::MatrixXd> partial_ddq, const RneaOptions& options) {
  const int n = model.dof();
  assert(q.size() == n && dq.size() == n && ddq.size() == n);
  assert(partial_q.rows() == n && partial_q.cols() == n && partial_dq.rows() == n &&
         partial_dq.cols() == n && partial_ddq.rows() == n && partial_ddq.cols() == n);
  // Entries of joints on different branches are zero and never written; a chain has none.
  if (2 * ws.depth_sum != n * (n + 1)) {
    partial_q.setZero();
    partial_dq.setZero();
    partial_ddq.setZero();
  }
  forward_kinematics(model, ws, q);  // world poses R_WJ, p_WJ
  const Vector3d zero = Vector3d::Zero();
  const Vector3d a0 = options.gravity ? Vector3d(-model.gravity) : zero;
  // Forward pass: the unit twists S_j, velocities and accelerations (gravity trick),
  // δ_j = S_j × v_λ and ψ_j = S_j × a_λ − δ_j × v_λ, and per body its inertia Y, momentum Y·v,
  // force Y·a + v ×* Y·v and inertia rate dY/dt = v ×* Y − Y·v×, the last three seeding the
  // composites of the subtree.
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model.joints[j];
    LinkState& s = ws.links[j];
    RneaDerivativeState& d = ws.derivative[j];
    const int parent = joint.parent;
    const Vector3d axis = s.R_WJ * joint.axis;
    if (joint.type == JointType::kRevolute) {
      d.S_w = axis;
      d.S_v = s.p_WJ.cross(axis);
    } else {
      d.S_w.setZero();
      d.S_v = axis;
    }
    const Vector3d& vp_w = parent < 0 ? zero : ws.derivative[parent].v_w;
    const Vector3d& vp_v = parent < 0 ? zero : ws.derivative[parent].v_v;
    const Vector3d& ap_w = parent < 0 ? zero : ws.derivative[parent].a_w;
    const Vector3d& ap_v = parent < 0 ? a0 : ws.derivative[parent].a_v;
    cross_motion(d.S_w, d.S_v, vp_w, vp_v, d.d_w, d.d_v);
    Vector3d t_w, t_v;
    cross_motion(d.S_w, d.S_v, ap_w, ap_v, d.psi_w, d.psi_v);
    cross_motion(d.d_w, d.d_v, vp_w, vp_v, t_w, t_v);
    d.psi_w -= t_w;
    d.psi_v -= t_v;
    d.v_w = vp_w + dq[j] * d.S_w;
    d.v_v = vp_v + dq[j] * d.S_v;
    // a = a_λ + S·q̈ + v_λ × S·q̇, and v_λ × S = −δ.
    d.a_w = ap_w + ddq[j] * d.S_w - dq[j] * d.d_w;
    d.a_v = ap_v + ddq[j] * d.S_v - dq[j] * d.d_v;
    const LinkParams& p = model.links[j];
    BodyInertia body;
    body.I << p(0), p(1), p(2), p(1), p(3), p(4), p(2), p(4), p(5);
    body.h = p.segment<3>(6);
    body.m = p(9);
    d.Y.I.setZero();
    d.Y.h.setZero();
    d.Y.m = 0.0;
    detail::add_to_parent(s.R_WJ, s.p_WJ, body, d.Y);
    const Vector3d& w = d.v_w;
    const Vector3d& v = d.v_v;
    inertia_action(d.Y, w, v, d.H_n, d.H_f);
    inertia_action(d.Y, d.a_w, d.a_v, d.F_n, d.F_f);
    Vector3d b_n, b_f;
    cross_force(w, v, d.H_n, d.H_f, b_n, b_f);
    d.F_n += b_n;
    d.F_f += b_f;
    // dY/dt of a body moving with twist (ω; v): İ = 2(h·v)·1 − (v·hᵀ + h·vᵀ) + [ω×]·I − I·[ω×],
    // dh/dt = m·v + ω × h, dm/dt = 0 (docs/methods/dynamics.md, "RNEA derivatives").
    const Eigen::Matrix3d vh = v * d.Y.h.transpose();
    Eigen::Matrix3d wI;
    for (int k = 0; k < 3; ++k) wI.col(k) = w.cross(d.Y.I.col(k));
    d.dY.I = wI + wI.transpose() - vh - vh.transpose();  // I·[ω×] = −([ω×]·I)ᵀ, I symmetric
    d.dY.I.diagonal().array() += 2.0 * d.Y.h.dot(v);
    d.dY.h = d.Y.m * v + w.cross(d.Y.h);
    d.dY.m = 0.0;
  }
  // Backward pass: when joint i is reached its composites over the subtree are complete. With
  // rY = Y·S_i, rD = dY·S_i, rH = S_i ×* H, for every k on the path from i to the root:
  //   ∂τ_i/∂q_k  = −ψ_k·rY + δ_k·(rH − rD),   ∂τ_i/∂q̇_k = S_k·(rD − rH) − 2δ_k·rY,
  //   ∂τ_i/∂q̈_k = S_k·rY,
  // and for strict ancestors k, ∂τ_k/∂q_i = S_k·g, ∂τ_k/∂q̇_i = S_k·e with
  //   g = S_i ×* F − Y·ψ_i − dY·δ_i − δ_i ×* H,   e = dY·S_i − 2Y·δ_i + S_i ×* H.
  for (int i = n - 1; i >= 0; --i) {
    const Joint& joint = model.joints[i];
    const RneaDerivativeState& d = ws.derivative[i];
    Vector3d rY_n, rY_f, rD_n, rD_f, rH_n, rH_f;
    inertia_action(d.Y, d.S_w, d.S_v, rY_n, rY_f);
    inertia_action(d.dY, d.S_w, d.S_v, rD_n, rD_f);
    cross_force(d.S_w, d.S_v, d.H_n, d.H_f, rH_n, rH_f);
    const Vector3d x_n = rH_n - rD_n, x_f = rH_f - rD_f;
    Vector3d g_n, g_f, e_n, e_f, t_n, t_f;
    cross_force(d.S_w, d.S_v, d.F_n, d.F_f, g_n, g_f);
    inertia_action(d.Y, d.psi_w, d.psi_v, t_n, t_f);
    g_n -= t_n;
    g_f -= t_f;
    inertia_action(d.dY, d.d_w, d.d_v, t_n, t_f);
    g_n -= t_n;
    g_f -= t_f;
    cross_force(d.d_w, d.d_v, d.H_n, d.H_f, t_n, t_f);
    g_n -= t_n;
    g_f -= t_f;
    inertia_action(d.Y, d.d_w, d.d_v, t_n, t_f);
    e_n = rD_n - 2.0 * t_n + rH_n;
    e_f = rD_f - 2.0 * t_f + rH_f;
    for (int k = i; k >= 0; k = model.joints[k].parent) {
      const RneaDerivativeState& dk = ws.derivative[k];
      partial_q(i, k) = dot(dk.d_w, dk.d_v, x_n, x_f) - dot(dk.psi_w, dk.psi_v, rY_n, rY_f);
      partial_dq(i, k) = -dot(dk.S_w, dk.S_v, x_n, x_f) - 2.0 * dot(dk.d_w, dk.d_v, rY_n, rY_f);
      partial_ddq(i, k) = partial_ddq(k, i) = dot(dk.S_w, dk.S_v, rY_n, rY_f);
      if (k != i) {
        partial_q(k, i) = dot(dk.S_w, dk.S_v, g_n, g_f);
        partial_dq(k, i) = dot(dk.S_w, dk.S_v, e_n, e_f);
      }
    }
    if (options.joint_terms) {
      const JointFriction& f = joint.friction;
      partial_ddq(i, i) += f.Ia;
      partial_dq(i, i) += f.Fv + f.Fva * detail::sign(dq[i]);
    }
    const int parent = joint.parent;
    if (parent < 0) continue;
    RneaDerivativeState& dp = ws.derivative[parent];
    add(d.Y, dp.Y);
    add(d.dY, dp.dY);
    dp.H_n += d.H_n;
    dp.H_f += d.H_f;
    dp.F_n += d.F_n;
    dp.F_f += d.F_f;
  }
}

}  // namespace dynid
