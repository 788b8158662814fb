#include "dynid/report/drift_report.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/version.hpp"

namespace dynid {

namespace {

std::string format(const char* f, double a, double b, double c, double d) {
  char buf[160];
  std::snprintf(buf, sizeof buf, f, a, b, c, d);
  return buf;
}

}  // namespace

DriftInput drift_input_of_result(const nlohmann::json& result, const std::string& path,
                                 std::string* covariance) {
  const auto bad = [&](const std::string& what) {
    throw Error("'" + path + "': " + what +
                "; give result JSONs of dynid identify, merge or payload");
  };
  if (!result.is_object() || !result.contains("parameters") || !result["parameters"].is_array()) {
    bad("no parameters list");
  }
  DriftInput in;
  in.label = path;
  const nlohmann::json& params = result["parameters"];
  const auto n = static_cast<Eigen::Index>(params.size());
  in.values.resize(n);
  in.std_devs.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const nlohmann::json& p = params[static_cast<std::size_t>(i)];
    if (!p.is_object() || !p.contains("name") || !p["name"].is_string() || !p.contains("value") ||
        !p["value"].is_number()) {
      bad("parameters[" + std::to_string(i) + "] has no name or no numeric value");
    }
    in.names.push_back(p["name"].get<std::string>());
    in.values[i] = p["value"].get<double>();
    // null = undetermined (json_number of an infinite σ): not tested.
    in.std_devs[i] = p.contains("std") && p["std"].is_number()
                         ? p["std"].get<double>()
                         : std::numeric_limits<double>::quiet_NaN();
  }
  if (covariance != nullptr) {
    covariance->clear();
    const auto choices = result.find("choices");
    if (choices != result.end() && choices->is_object() && choices->contains("covariance") &&
        (*choices)["covariance"].is_string()) {
      *covariance = (*choices)["covariance"].get<std::string>();
    } else if (result.contains("covariance") && result["covariance"].is_string()) {
      *covariance = result["covariance"].get<std::string>();
    }
  }
  return in;
}

std::string robot_of_result(const nlohmann::json& result) {
  const auto model = result.find("model");
  if (model != result.end() && model->is_object() && model->contains("name") &&
      (*model)["name"].is_string()) {
    return (*model)["name"].get<std::string>();
  }
  return {};
}

nlohmann::json drift_to_json(const std::vector<DriftInput>& inputs,
                             const std::vector<std::string>& covariances,
                             const std::vector<std::string>& robots, const DriftComparison& c) {
  nlohmann::json results = nlohmann::json::array();
  for (std::size_t r = 0; r < inputs.size(); ++r) {
    results.push_back({{"file", inputs[r].label},
                       {"covariance", r < covariances.size() ? covariances[r] : ""},
                       {"robot", r < robots.size() ? robots[r] : ""}});
  }
  nlohmann::json parameters = nlohmann::json::array(), flagged = nlohmann::json::array();
  nlohmann::json friction = nlohmann::json::array(), payload = nlohmann::json::array();
  const std::size_t later = inputs.size() - 1;
  for (std::size_t i = 0; i < c.rows.size(); i += later) {
    const ParameterDrift& first = c.rows[i];
    // json::array() explicitly: `json v = {x}` with one json x is a copy under clang, an array
    // under gcc (CWG 2137), so the later push_back threw on clang builds only.
    nlohmann::json values = nlohmann::json::array(), stds = nlohmann::json::array();
    values.push_back(json_number(first.before));
    const DriftInput& base = inputs.front();
    for (std::size_t k = 0; k < base.names.size(); ++k) {
      if (base.names[k] == first.name) stds.push_back(json_number(base.std_devs[k]));
    }
    nlohmann::json comparisons = nlohmann::json::array();
    for (std::size_t r = 0; r < later; ++r) {
      const ParameterDrift& d = c.rows[i + r];
      values.push_back(json_number(d.after));
      const DriftInput& in = inputs[static_cast<std::size_t>(d.result)];
      for (std::size_t k = 0; k < in.names.size(); ++k) {
        if (in.names[k] == d.name) stds.push_back(json_number(in.std_devs[k]));
      }
      comparisons.push_back({{"result", d.result},
                             {"change", json_number(d.change)},
                             {"std", json_number(d.std_dev)},
                             {"z", json_number(d.z)},
                             {"p_value", json_number(d.p_value)},
                             {"p_adjusted", json_number(d.p_adjusted)},
                             {"tested", d.tested},
                             {"flagged", d.flagged}});
      if (!d.flagged) continue;
      flagged.push_back({{"name", d.name},
                         {"role", to_string(d.role)},
                         {"result", d.result},
                         {"file", in.label},
                         {"change", json_number(d.change)},
                         {"std", json_number(d.std_dev)},
                         {"z", json_number(d.z)},
                         {"p_adjusted", json_number(d.p_adjusted)}});
      nlohmann::json& list = d.role == ParameterRole::kFriction ? friction : payload;
      if ((d.role == ParameterRole::kFriction || d.role == ParameterRole::kPayload) &&
          std::find(list.begin(), list.end(), d.name) == list.end())
        list.push_back(d.name);
    }
    parameters.push_back({{"name", first.name},
                          {"role", to_string(first.role)},
                          {"values", values},
                          {"std", stds},
                          {"comparisons", comparisons}});
  }
  return {{"command", "compare"},
          {"alpha", c.alpha},
          {"correction", "holm"},
          {"tests", c.tests},
          {"first_critical_z", json_number(c.first_critical_z)},
          {"results", results},
          {"parameters", parameters},
          {"flagged", flagged},
          {"flagged_friction", friction},
          {"flagged_payload", payload},
          {"not_shared", c.not_shared},
          {"version", kVersion}};
}

std::string drift_table(const std::vector<DriftInput>& inputs, const DriftComparison& c) {
  std::ostringstream s;
  s << "baseline " << inputs.front().label << "; " << c.tests
    << " tests (parameter x later result), family-wise false-alarm rate " << c.alpha
    << " (Holm); |z| > " << format("%.3g", c.first_critical_z, 0, 0, 0)
    << " flags at the first step\n";
  std::size_t shown = 0;
  for (const ParameterRole role : {ParameterRole::kFriction, ParameterRole::kPayload,
                                   ParameterRole::kArmature, ParameterRole::kInertial}) {
    for (const ParameterDrift& d : c.rows) {
      if (!d.flagged || d.role != role) continue;
      if (shown++ == 0) {
        s << "significant changes:\n";
      }
      s << "  " << inputs[static_cast<std::size_t>(d.result)].label << "  " << d.name << " ("
        << to_string(d.role) << ")  "
        << format("%.6g -> %.6g, change %.4g +- %.3g", d.before, d.after, d.change, d.std_dev)
        << format(" (z %.3g, adjusted p %.3g)\n", d.z, d.p_adjusted, 0, 0);
    }
  }
  if (shown == 0) s << "no significant change\n";
  if (!c.not_shared.empty()) {
    s << "not compared (not in every result):";
    for (const auto& n : c.not_shared) s << ' ' << n;
    s << '\n';
  }
  return s.str();
}

}  // namespace dynid
