#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/estimation/identification.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/model.hpp"
#include "dynid/sim/simulation_validation.hpp"

namespace dynid {

/// The result JSON of DESIGN.md §4 / issue 4: model summary, `parameters` (name, value, std,
/// relative_std_percent, ci_low, ci_high, expression), `confidence_level`, `rank`,
/// `condition_number`, `samples`, `rows`, `residual_rms` and `joint_relative_error` per joint,
/// `relative_error`, `unidentifiable`, `warnings`, `choices` (every processing decision), `options`
/// as given and `version`. Non-finite numbers become null.
nlohmann::json identification_to_json(const Model& model, const IdentificationResult& result,
                                      const nlohmann::json& options_used);

/// A readable table: name, value, σ, %σ, confidence interval; then rank, condition number and the
/// per-joint residuals and warnings.
std::string identification_table(const Model& model, const IdentificationResult& result);

/// Reads `parameters[].name/value` of a result JSON (identification_to_json). Throws dynid::Error
/// naming the file when the key is missing or malformed.
void read_identified_parameters(const std::string& path, std::vector<std::string>& names,
                                Eigen::VectorXd& values, nlohmann::json& options_used);

/// The base-parameter section of `dynid model --base`: `base_parameters` (name, expression),
/// `unidentifiable`, `rank`, and the text version.
nlohmann::json base_parameters_to_json(const BaseParameters& base);
std::string base_parameters_text(const BaseParameters& base);

/// `dynid validate` JSON: `joints` (name, rms, relative_error), `relative_error`, `samples`.
nlohmann::json validation_to_json(const Model& model, const ValidationResult& v);
std::string validation_table(const Model& model, const ValidationResult& v);

/// `dynid validate --mode simulation` JSON: `joints` (name, position {rms, max, mean, std,
/// skewness, kurtosis, ks_statistic, ks_p_value}, torque {same}), `samples`, `version`.
nlohmann::json simulation_validation_to_json(const Model& model, const SimulationValidation& v);
std::string simulation_validation_table(const Model& model, const SimulationValidation& v);

}  // namespace dynid
