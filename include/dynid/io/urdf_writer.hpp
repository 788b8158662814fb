#pragma once

#include <string>

#include "dynid/model/model.hpp"

namespace dynid {

/// Options of the URDF export.
struct UrdfWriteOptions {
  std::string root_link = "base_link";  ///< name of the fixed root link
  bool mujoco_compiler_tag = false;  ///< add <mujoco><compiler …/></mujoco> so MuJoCo keeps every
                                     ///< body and inertia exactly as written
};

/// Mass, centre of mass and inertia about the centre of mass of one link, as URDF's <inertial>.
struct ComInertial {
  double mass = 0.0;                                  ///< [kg]
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      ///< in the link frame [m]; 0 if massless
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  ///< about com, link-frame axes [kg·m²]
};

/// Inverse of link_params_from_com (parallel-axis theorem, seed 1 eq. 24): I_C = I_O −
/// m(|c|²·1 − c·cᵀ) with c = (MX, MY, MZ)/m. A massless link keeps its inertia about the origin.
ComInertial com_inertial(const LinkParams& p);

/// Writes the model as URDF text: one joint per Model joint (revolute with ±inf limits becomes
/// continuous), origins as xyz/rpy, inertials about the centre of mass with the full tensor in the
/// link frame (standard parameters converted back by the parallel-axis theorem), <dynamics damping
/// friction> from Fv and Fc. Massless links keep their rotational inertia.
/// Round trip: load_urdf(to_urdf(model)) reproduces the dynamics (the loader merges nothing).
std::string to_urdf(const Model& model, const UrdfWriteOptions& options = {});

/// to_urdf written atomically to `path` (temporary file, then rename). Throws dynid::Error when the
/// file cannot be written.
void write_urdf(const Model& model, const std::string& path, const UrdfWriteOptions& options = {});

}  // namespace dynid
