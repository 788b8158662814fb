#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/workspace.hpp"

namespace dynid {

/// Which terms the inverse dynamics includes.
struct RneaOptions {
  bool gravity = true;      ///< include the model's gravity
  bool joint_terms = true;  ///< include Ia·ddq + Fv·dq + Fc·sign(dq) + Fo from Joint::friction
};

/// Recursive Newton–Euler inverse dynamics (Luh–Walker–Paul; Khalil–Dombre ch. 9) on the tree:
/// tau = M(q)·ddq + c(q, dq) + g(q) [+ Ia·ddq + Fv·dq + Fc·sign(dq) + Fo], the joint-side
/// torque (N·m) or force (N). q, dq, ddq, tau: size n. Equals Y(q, dq, ddq)·theta (regressor).
/// No allocation; sizes are checked with assertions only (hot path).
void rnea(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
          const Eigen::Ref<const Eigen::VectorXd>& dq, const Eigen::Ref<const Eigen::VectorXd>& ddq,
          Eigen::Ref<Eigen::VectorXd> tau, const RneaOptions& options = {});

/// Convenience overload that allocates its workspace and result.
Eigen::VectorXd rnea(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& dq,
                     const Eigen::VectorXd& ddq, const RneaOptions& options = {});

}  // namespace dynid
