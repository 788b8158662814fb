#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid {

/// Which per-joint columns follow the 10·n link parameters (docs/design.md section 3). For each
/// joint j, in this order: Iaj, then Fvj Fcj (or Fvpj Fvnj Fcpj Fcnj when asymmetric), then Foj.
struct ParameterLayout {
  bool armature = false;    ///< Iaj: tau_j += Ia_j·ddq_j
  bool viscous = false;     ///< Fvj: tau_j += Fv_j·dq_j
  bool coulomb = false;     ///< Fcj: tau_j += Fc_j·sign(dq_j)
  bool offset = false;      ///< Foj: tau_j += Fo_j
  bool asymmetric = false;  ///< seed 2 eq. 2: Fvp/Fvn and Fcp/Fcn per direction of motion

  /// All per-joint terms (armature, viscous, coulomb, offset), symmetric friction.
  static ParameterLayout full();
  /// Rigid body only (10·n columns).
  static ParameterLayout rigid() { return {}; }

  int joint_columns() const;  ///< number of columns per joint after the link parameters
  int columns(int dof) const { return kLinkParams * dof + joint_columns() * dof; }

  /// Parameter names in column order: XX1 … M_n, then Ia1 Fv1 Fc1 Fo1 Ia2 …
  std::vector<std::string> names(int dof) const;

  /// The model's own values in this layout (link parameters, then Joint::friction; asymmetric
  /// columns take the symmetric values for both directions).
  Eigen::VectorXd parameters(const Model& model) const;
};

/// The SI unit of a parameter named as ParameterLayout::names() and the base-parameter names make
/// them (XX1 … M6, Ia2, Fvp3, Fc2R: a trailing R marks a regrouped base parameter, whose terms
/// share the unit of the first): kg·m², kg·m, kg for link parameters; for joint j's terms (and
/// coupled motor j's Iam, Fvm, Fcm) those of its type, revolute Ia kg·m², Fv N·m·s/rad, Fc and Fo
/// N·m, prismatic kg, N·s/m, N. Empty for a name of another form or a joint outside the model. No
/// errors.
std::string parameter_unit(const Model& model, const std::string& name);

}  // namespace dynid
