#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid {

/// The physically consistent standard parameters of a result JSON (`dynid identify --physical`).
struct ConsistentParameterFile {
  std::vector<std::string> names;   ///< `standard_parameters[].name` (docs/design.md §3 names)
  Eigen::VectorXd values;           ///< `standard_parameters[].value`, SI units
  std::string robot;                ///< `model.name`; empty when the file has none
  std::vector<std::string> joints;  ///< `model.joints`; empty when the file has none
  std::vector<JointLock> locked_joints;  ///< `locked_joints`: joints identify held fixed
};

/// Reads `standard_parameters` of a result JSON. Throws dynid::Error naming the file when it cannot
/// be read or parsed, has no `standard_parameters` (not written with --physical), is not
/// `physically_consistent`, or holds a malformed or non-finite entry.
ConsistentParameterFile read_consistent_parameters(const std::string& path);

/// An identified model written as URDF, and what the URDF could not hold.
struct UrdfExport {
  Model model;       ///< nominal model with the identified standard parameters, finalized
  std::string text;  ///< the URDF
  /// Identified terms URDF has no element for, as `name = value (reason)`: armature Ia (no URDF
  /// element), offset Fo, asymmetric friction (written as the mean of both directions), coupled
  /// motor terms Iam/Fvm/Fcm, and a gravity other than (0, 0, −9.81).
  std::vector<std::string> not_in_urdf;
  /// Links fixed to a moving link whose <inertial> was removed: the identification sees the rigid
  /// group as one body, whose identified inertia goes to the moving link.
  std::vector<std::string> merged_links;
};

/// The nominal model with every link's standard parameters and every Iaj/Fvj/Fcj/Foj replaced by
/// the named values (asymmetric pairs Fvpj/Fvnj, Fcpj/Fcnj set Fv/Fc to their mean; coupled-motor
/// columns Iam/Fvm/Fcm are ignored here), then finalize()d. Every link's 10 parameters must be
/// given. Throws dynid::Error for an unknown name, a missing link parameter, a size mismatch, and
/// for a non-physical link (Model::finalize).
Model model_with_standard_parameters(const Model& nominal, const std::vector<std::string>& names,
                                     const Eigen::VectorXd& values);

/// The identified model as URDF. When `nominal.source` is a .urdf file, that file's XML is edited:
/// each moving joint's child link gets <inertial> (mass, centre of mass, inertia about the centre
/// of mass in the link frame, which is the URDF joint frame), the <inertial> of links fixed to it
/// is removed (merged_links), and each joint whose Fv/Fc was identified gets <dynamics damping
/// friction>; every other element and attribute is kept. Otherwise (MDH/YAML models) to_urdf()
/// writes the same frames. A comment after <robot> names `origin` (the result file) and lists
/// not_in_urdf. Throws dynid::Error as model_with_standard_parameters, and when the URDF cannot be
/// read or a model joint is not in it.
UrdfExport export_urdf(const Model& nominal, const std::vector<std::string>& names,
                       const Eigen::VectorXd& values, const std::string& origin);

}  // namespace dynid
