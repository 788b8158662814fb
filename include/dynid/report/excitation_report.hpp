#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/excitation/excitation_optimization.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// `dynid excite --json`: `criterion`, `value`, `condition_number`, `log_det`,
/// `constraints_satisfied`, `margins` (name, margin, time, limit, reached, unit, relative),
/// `coefficients` (f0, a, b, q0),
/// `base_parameters`, `evaluations`, `seconds`, `version`.
nlohmann::json excitation_to_json(const ExcitationResult& result);

/// Writes sampled joint signals as CSV with columns t, q1..qn, dq1..dqn, ddq1..ddqn (atomic).
void write_trajectory_csv(const std::string& path, const TrajectorySamples& samples);

/// One-paragraph summary of an excitation result (criterion reached, constraints, worst margins).
std::string excitation_text(const ExcitationResult& result);

}  // namespace dynid
