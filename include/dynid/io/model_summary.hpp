#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/model/model.hpp"

namespace dynid {

/// The model as JSON (`dynid model --json`, docs/cli.md): name, source, dof, gravity [m/s²],
/// joints (list of {name, link, type, parent (joint name or null for the base), lower, upper,
/// velocity, effort}; infinite limits are null), standard_parameters (list of {name, value} in
/// Model::standard_parameter_names() order, SI units about each link origin), friction (one
/// {joint, Ia, Fv, Fc, Fo} per joint), transmission {N (list of rows), q_offset}, version.
nlohmann::json model_to_json(const Model& model);

/// A readable multi-line summary of the same content (`dynid model`).
std::string model_summary_text(const Model& model);

}  // namespace dynid
