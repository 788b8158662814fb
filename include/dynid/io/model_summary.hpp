#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynid/model/model.hpp"

namespace dynid {

/// The model as JSON (`dynid model --json`, docs/cli.md): name, source, dof, gravity [m/s²],
/// joints (list of {name, link, type, parent (joint name or null for the base), lower, upper,
/// velocity, effort}; infinite limits are null), standard_parameters (list of {name, value} in
/// Model::standard_parameter_names() order, SI units about each link origin), friction (one
/// {joint, Ia, Fv, Fc, Fo} per joint), transmission {N (list of rows), q_offset}, locked_joints
/// (locked_joints_to_json), version.
nlohmann::json model_to_json(const Model& model);

/// `locked_joints` of every result JSON (issue 26 item 1): [{name, value}] of
/// Model::locked_joints, in model order, values in rad or m; [] when no joint is locked.
nlohmann::json locked_joints_to_json(const Model& model);

/// `locked_joints` of a result JSON read back (absent: none). Throws dynid::Error naming `path`
/// when it is not a list of {name: string, value: finite number}.
std::vector<JointLock> locked_joints_from_json(const nlohmann::json& result,
                                               const std::string& path);

/// A readable multi-line summary of the same content (`dynid model`).
std::string model_summary_text(const Model& model);

}  // namespace dynid
