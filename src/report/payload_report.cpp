#include "dynid/report/payload_report.hpp"

#include <algorithm>
#include <cmath>

#include "dynid/io/json_writer.hpp"
#include "dynid/version.hpp"

namespace dynid {

namespace {

nlohmann::json parameter_json(const LoadIdentificationResult& r) {
  nlohmann::json list = nlohmann::json::array();
  const Estimate& e = r.estimate;
  for (std::size_t j = 0; j < r.names.size(); ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    list.push_back({{"name", r.names[j]},
                    // A parameter the data do not determine has no value worth a number.
                    {"value", std::isfinite(e.std_dev(i)) ? json_number(e.x(i)) : nlohmann::json()},
                    {"std", json_number(e.std_dev(i))},
                    {"relative_std_percent", json_number(e.relative_std_percent(i))},
                    {"ci_low", json_number(e.ci_lower(i))},
                    {"ci_high", json_number(e.ci_upper(i))}});
  }
  return list;
}

}  // namespace

nlohmann::json payload_to_json(const LoadIdentificationResult& r,
                               const PayloadJsonContext& context) {
  const Estimate& e = r.estimate;
  const bool mass_known =
      std::find(r.not_excited.begin(), r.not_excited.end(), "m") == r.not_excited.end();
  nlohmann::json out = {
      {"command", "payload"},
      {"model", context.model},
      {"estimator", to_string(e.summary.estimator)},
      {"frame", context.frame},
      {"confidence_level", e.confidence_level},
      {"covariance", e.covariance_kind},
      {"parameters", parameter_json(r)},
      {"mass", mass_known ? json_number(e.x(0)) : nlohmann::json()},
      {"com", r.physics.mass > 0.0
                  ? nlohmann::json{json_number(r.physics.com.x()), json_number(r.physics.com.y()),
                                   json_number(r.physics.com.z())}
                  : nlohmann::json()},
      {"physically_consistent", r.physics.consistent},
      {"consistency_violation", r.physics.violated},
      {"not_excited", r.not_excited},
      {"residual_rms", json_number(e.residual_rms)},
      {"relative_error", json_number(e.relative_error)},
      {"condition_number", json_number(e.summary.condition_number)},
      {"rows", e.summary.rows},
      {"warnings", e.summary.warnings},
      {"version", kVersion}};
  out.update(context.extra);
  if (context.with_inertia && r.physics.mass > 0.0) {
    const Eigen::Matrix3d& I = r.physics.inertia_com;
    out["inertia_com"] = {{"Ixx", I(0, 0)}, {"Ixy", I(0, 1)}, {"Ixz", I(0, 2)},
                          {"Iyy", I(1, 1)}, {"Iyz", I(1, 2)}, {"Izz", I(2, 2)}};
  } else {
    out["inertia_com"] = nullptr;
    if (!context.with_inertia) {
      out["not_reported"] =
          "inertias: standing poses determine only the mass, the first moments "
          "and the offsets";
    }
  }
  nlohmann::json per_component = nlohmann::json::object();
  for (std::size_t c = 0; c < context.group_names.size(); ++c) {
    per_component[context.group_names[c]] =
        json_number(e.group_rms.size() ? e.group_rms(static_cast<Eigen::Index>(c)) : NAN);
  }
  out["residual_rms_per_component"] = per_component;
  nlohmann::json choice_json = nlohmann::json::object();
  for (const auto& [key, value] : context.choices) choice_json[key] = value;
  out["choices"] = choice_json;
  return out;
}

}  // namespace dynid
