#pragma once

#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynid/load/load_identification.hpp"

namespace dynid {

/// How a load result was obtained: what payload_to_json() writes beside the estimate.
struct PayloadJsonContext {
  /// `model`: "differential", "integral", "static" (wrist sensor) or "joint_torques".
  std::string model = "differential";
  /// `frame`: where the parameters are expressed ({robot, sensor_link}, {orientation}, or
  /// {robot, link, frame} for a load from joint torques).
  nlohmann::json frame = nlohmann::json::object();
  /// Further top-level keys (wrench_sign, interval, reference, determined_by_torques).
  nlohmann::json extra = nlohmann::json::object();
  /// Names of the residual groups (fx … mz, or the joints), keys of
  /// `residual_rms_per_component`.
  std::vector<std::string> group_names;
  /// False for standing poses: the inertias are not determined and `not_reported` says so.
  bool with_inertia = true;
  /// Processing decisions (`choices`), in order.
  std::vector<std::pair<std::string, std::string>> choices;
};

/// The `dynid payload` result JSON (docs/cli.md): `command`, `model`, `estimator`, `frame`,
/// `confidence_level`, `covariance`, `parameters` (name, value — null when σ is not finite —,
/// std, relative_std_percent, ci_low, ci_high), `mass`, `com` [m], `inertia_com` {Ixx … Izz}
/// about the centre of mass [kg·m²] (seed 1 eq. 24) or null, `physically_consistent`,
/// `consistency_violation`, `not_excited`, `residual_rms`, `relative_error`, `condition_number`,
/// `rows`, `warnings`, `residual_rms_per_component`, `choices`, `version`, plus `context.extra`.
/// Shared by the CLI and the Python module so that their keys cannot drift apart. Non-finite
/// numbers become null; never throws for a result of identify_load().
nlohmann::json payload_to_json(const LoadIdentificationResult& result,
                               const PayloadJsonContext& context);

}  // namespace dynid
