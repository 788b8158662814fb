#pragma once

// `dynid compare` (issue 31 item 3): result JSONs read for compare_estimates(), the comparison as
// JSON and as a table. The HTML page is html_report()'s section of kind "compare".

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynid/estimation/parameter_drift.hpp"

namespace dynid {

/// A result JSON (identify, merge or payload: `parameters` with `name`, `value`, `std`) as a
/// DriftInput labelled `path`, and the covariance it states (`choices.covariance`, or the
/// payload's `covariance`; empty when the result does not say). Throws dynid::Error naming the
/// file when `parameters` is missing or malformed.
DriftInput drift_input_of_result(const nlohmann::json& result, const std::string& path,
                                 std::string* covariance = nullptr);

/// The robot a result names (`model.name`, empty when none).
std::string robot_of_result(const nlohmann::json& result);

/// The JSON of `dynid compare`: `command` "compare", `alpha`, `correction` "holm", `tests`,
/// `first_critical_z`, `results` (file, covariance, robot), `parameters` (name, role, values per
/// result, std per result, and `comparisons` against the first: result, change, std, z, p_value,
/// p_adjusted, tested, flagged), `flagged` (name, role, result, file, change, std, z,
/// p_adjusted), `flagged_friction` and `flagged_payload` (names), `not_shared`, `version`.
/// Non-finite numbers are null.
nlohmann::json drift_to_json(const std::vector<DriftInput>& inputs,
                             const std::vector<std::string>& covariances,
                             const std::vector<std::string>& robots, const DriftComparison& c);

/// The text summary: the rule, then one line per flagged parameter (friction and payload first),
/// then "no significant change" when none.
std::string drift_table(const std::vector<DriftInput>& inputs, const DriftComparison& c);

}  // namespace dynid
