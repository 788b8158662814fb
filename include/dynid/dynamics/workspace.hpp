#pragma once

#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "dynid/model/model.hpp"

namespace dynid {

/// Per-link kinematic state, every vector expressed in link frame j (monogram: _J).
struct LinkState {
  Eigen::Matrix3d R_PJ;  ///< orientation of frame j in its parent frame at the current q
  Eigen::Vector3d p_PJ;  ///< origin of frame j in its parent frame at the current q [m]
  /// Orientation of frame j in the base (world) frame. R_WJ and p_WJ are set by
  /// forward_kinematics only: rnea, the mass matrix and the regressors leave them as they were.
  Eigen::Matrix3d R_WJ;
  Eigen::Vector3d p_WJ;  ///< origin of frame j in the base frame [m] (see R_WJ)
  Eigen::Vector3d w;     ///< angular velocity of link j [rad/s]
  Eigen::Vector3d v;     ///< linear velocity of origin j [m/s]
  Eigen::Vector3d dw;    ///< angular acceleration [rad/s²]
  Eigen::Vector3d a;     ///< linear acceleration of origin j MINUS gravity [m/s²] (gravity trick)
  Eigen::Vector3d f;     ///< force link parent(j) exerts on link j (backward pass) [N]
  Eigen::Vector3d n;     ///< moment about origin j that parent(j) exerts on link j [N·m]
};

/// Spatial inertia of a body (or a composite of bodies) about a frame's origin, in that frame: the
/// rotational inertia about the origin, the first moment m·c and the mass. The 6×6 matrix
/// [[I, [h×]], [−[h×], m·1]] it stands for is never formed.
struct BodyInertia {
  Eigen::Matrix3d I;  ///< rotational inertia about the origin [kg·m²]
  Eigen::Vector3d h;  ///< first moment m·c [kg·m]
  double m = 0.0;     ///< mass [kg]
};

/// State of link j in the articulated-body algorithm (Featherstone 2008, Table 7.1), in frame j
/// about origin j, for spatial motion (ω; v_O) and force (n_O; f). The articulated inertia
/// [[A, B], [Bᵀ, C]] is kept as its three 3×3 blocks.
struct ArticulatedBody {
  Eigen::Matrix3d A;         ///< rotational block (symmetric) [kg·m²]
  Eigen::Matrix3d B;         ///< coupling block [kg·m]
  Eigen::Matrix3d C;         ///< translational block (symmetric) [kg]
  Eigen::Vector3d p_n, p_f;  ///< bias force p^A: moment about origin j [N·m], force [N]
  Eigen::Vector3d c_w, c_v;  ///< velocity-product acceleration c_j [rad/s², m/s²]
  Eigen::Vector3d U_n, U_f;  ///< U = I^A·S [kg·m² or kg·m; kg·m or kg]
  Eigen::Vector3d a_w, a_v;  ///< spatial acceleration of link j, minus gravity [rad/s², m/s²]
  double D = 0.0;            ///< Sᵀ·I^A·S + Ia [kg·m² or kg]
  double u = 0.0;            ///< τ − Sᵀ·p^A − friction [N·m or N]
};

/// State of link j in rnea_derivatives (Carpentier–Mansard style, world frame about the world
/// origin): motion (ω; v_O), force (n_O; f), composite quantities over the subtree of j.
struct RneaDerivativeState {
  Eigen::Vector3d S_w, S_v;      ///< unit twist of joint j
  Eigen::Vector3d v_w, v_v;      ///< spatial velocity of link j
  Eigen::Vector3d a_w, a_v;      ///< spatial acceleration of link j, minus gravity
  Eigen::Vector3d d_w, d_v;      ///< δ_j = S_j × v_parent
  Eigen::Vector3d psi_w, psi_v;  ///< ψ_j = S_j × a_parent − δ_j × v_parent
  Eigen::Vector3d H_n, H_f;      ///< composite momentum Σ Y_l·v_l
  Eigen::Vector3d F_n, F_f;      ///< composite force Σ (Y_l·a_l + v_l ×* Y_l·v_l)
  BodyInertia Y;                 ///< composite inertia Σ Y_l (world, about the world origin)
  BodyInertia dY;                ///< composite inertia rate Σ dY_l/dt (its m is 0)
};

/// Reusable scratch memory for one model and one thread. Construct once, pass to every call: the
/// algorithms then never allocate.
struct Workspace {
  explicit Workspace(const Model& model);
  std::vector<LinkState> links;
  std::vector<std::vector<int>> ancestors;  ///< ancestors[j]: j, parent(j), …, up to the root joint
  /// twists[j][k]: unit twist (ω; v at origin j) of joint ancestors[j][k], expressed in frame j.
  std::vector<std::vector<Eigen::Matrix<double, 6, 1>>> twists;
  std::vector<BodyInertia> composite;  ///< composite inertias of the subtrees (CRBA)
  /// subtree_end[j]: one past the last descendant of joint j (parents precede children), so the
  /// subtree of j lies in [j, subtree_end[j]); it is exactly that range when `depth_first`.
  std::vector<int> subtree_end;
  bool depth_first = true;  ///< joints in depth-first order: every subtree is a contiguous range
  int depth_sum = 0;        ///< Σ_j depth of joint j (ancestors[j].size()): n(n+1)/2 for a chain
  Eigen::MatrixXd forces;   ///< n×6 CRBA column forces (n; f), one column per component
  Eigen::MatrixXd scratch_nn;                   ///< n×n scratch (mass matrix, its LᵀDL factor)
  Eigen::VectorXd scratch_n;                    ///< n scratch
  Eigen::VectorXd scratch_n2;                   ///< n scratch
  std::vector<ArticulatedBody> articulated;     ///< articulated-body algorithm state
  std::vector<RneaDerivativeState> derivative;  ///< rnea_derivatives state
};

}  // namespace dynid
