#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "dynid/model/model.hpp"

namespace dynid::detail {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return S;
}

/// Spatial inertia about the link origin for motion (ω; v_O): [[I_O, [mc×]], [−[mc×], m·1]].
inline Matrix6d spatial_inertia(const LinkParams& p) {
  Matrix6d I = Matrix6d::Zero();
  I.topLeftCorner<3, 3>() = inertia_about_origin(p);
  const Eigen::Matrix3d C = skew(p.segment<3>(6));
  I.topRightCorner<3, 3>() = C;
  I.bottomLeftCorner<3, 3>() = -C;
  I.bottomRightCorner<3, 3>() = p(9) * Eigen::Matrix3d::Identity();
  return I;
}

/// Motion transform from the parent frame to frame j, for (ω; v_O) twists: ω' = Rᵀω,
/// v' = Rᵀ(v + ω × p), where (R, p) is the pose of frame j in the parent.
inline Matrix6d motion_transform(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  Matrix6d X = Matrix6d::Zero();
  const Eigen::Matrix3d Rt = R.transpose();
  X.topLeftCorner<3, 3>() = Rt;
  X.bottomRightCorner<3, 3>() = Rt;
  X.bottomLeftCorner<3, 3>() = -Rt * skew(p);
  return X;
}

/// Unit twist of a joint in its own frame: (axis; 0) revolute, (0; axis) prismatic.
inline Vector6d joint_twist(const Joint& joint) {
  Vector6d S = Vector6d::Zero();
  if (joint.type == JointType::kRevolute) {
    S.head<3>() = joint.axis;
  } else {
    S.tail<3>() = joint.axis;
  }
  return S;
}

}  // namespace dynid::detail
