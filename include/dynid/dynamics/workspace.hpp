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
  bool depth_first = true;     ///< joints in depth-first order: every subtree is a contiguous range
  Eigen::MatrixXd forces;      ///< n×6 CRBA column forces (n; f), one column per component
  Eigen::MatrixXd scratch_nn;  ///< n×n scratch (mass matrix, its LᵀDL factor)
  Eigen::VectorXd scratch_n;   ///< n scratch
  Eigen::VectorXd scratch_n2;  ///< n scratch
};

}  // namespace dynid
