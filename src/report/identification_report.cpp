#include "dynid/report/identification_report.hpp"

#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/version.hpp"

namespace dynid {

namespace {

std::vector<std::string> joint_names(const Model& model) {
  std::vector<std::string> out;
  for (const Joint& j : model.joints) out.push_back(j.name);
  return out;
}

nlohmann::json numbers(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(json_number(v[i]));
  return a;
}

std::string line(const char* format, ...) __attribute__((format(printf, 1, 2)));
std::string line(const char* format, ...) {
  char buf[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buf, sizeof(buf), format, args);
  va_end(args);
  return buf;
}

}  // namespace

nlohmann::json identification_to_json(const Model& model, const IdentificationResult& r,
                                      const nlohmann::json& options_used) {
  const Estimate& e = r.estimate;
  nlohmann::json params = nlohmann::json::array();
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    params.push_back({{"name", r.names[i]},
                      {"value", json_number(e.x[k])},
                      {"std", json_number(e.std_dev[k])},
                      {"relative_std_percent", json_number(e.relative_std_percent[k])},
                      {"ci_low", json_number(e.ci_lower[k])},
                      {"ci_high", json_number(e.ci_upper[k])},
                      {"expression", r.expressions[i]}});
    if (e.std_dev_white.size() == e.x.size()) {
      params.back()["std_white"] = json_number(e.std_dev_white[k]);
      params.back()["ci_white_low"] = json_number(e.ci_lower_white[k]);
      params.back()["ci_white_high"] = json_number(e.ci_upper_white[k]);
    }
  }
  nlohmann::json choices = nlohmann::json::object();
  for (const auto& [k, v] : r.choices) choices[k] = v;
  return {{"model",
           {{"name", model.name},
            {"source", model.source},
            {"dof", model.dof()},
            {"joints", joint_names(model)}}},
          {"parameters", params},
          {"confidence_level", e.confidence_level},
          {"rank", r.rank},
          {"condition_number", json_number(r.condition_number)},
          {"samples", r.samples},
          {"rows", r.rows},
          {"residual_rms", numbers(r.residual_rms)},
          {"joint_relative_error", numbers(r.joint_relative_error)},
          {"residual_autocorrelation", numbers(r.residual_autocorrelation)},
          {"relative_error", json_number(r.relative_error)},
          {"residual_variance", json_number(e.residual_variance)},
          {"estimator", to_string(e.summary.estimator)},
          {"unidentifiable", r.unidentifiable},
          {"warnings", r.warnings},
          {"choices", choices},
          {"options", options_used},
          {"version", kVersion}};
}

std::string identification_table(const Model& model, const IdentificationResult& r) {
  const Estimate& e = r.estimate;
  std::ostringstream s;
  s << line("%-10s %14s %12s %9s   %-29s\n", "parameter", "value", "std", "%std",
            (line("%.4g", 100 * e.confidence_level) + "% confidence interval").c_str());
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    s << line("%-10s %14.6g %12.4g %9.2f   [%.6g, %.6g]\n", r.names[i].c_str(), e.x[k],
              e.std_dev[k], e.relative_std_percent[k], e.ci_lower[k], e.ci_upper[k]);
  }
  s << line(
      "\nrank %d, condition number %.4g, %ld samples, %ld equations, relative error %.2f %%\n",
      r.rank, r.condition_number, static_cast<long>(r.samples), static_cast<long>(r.rows),
      100 * r.relative_error);
  for (int j = 0; j < model.dof(); ++j) {
    s << line("  %-12s residual RMS %.4g, relative error %.2f %%\n", model.joints[j].name.c_str(),
              r.residual_rms[j], 100 * r.joint_relative_error[j]);
  }
  for (const auto& w : r.warnings) s << "warning: " << w << '\n';
  return s.str();
}

void read_identified_parameters(const std::string& path, std::vector<std::string>& names,
                                Eigen::VectorXd& values, nlohmann::json& options_used) {
  std::ifstream f(path);
  if (!f)
    throw Error("cannot open parameter file '" + path +
                "'; give the result.json of dynid identify");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(f);
  } catch (const std::exception& ex) {
    throw Error("'" + path + "' is not valid JSON (" + std::string(ex.what()) + ")");
  }
  if (!j.contains("parameters") || !j["parameters"].is_array()) {
    throw Error("'" + path + "' has no 'parameters' list; give the result.json of dynid identify");
  }
  names.clear();
  values.resize(static_cast<Eigen::Index>(j["parameters"].size()));
  for (size_t i = 0; i < j["parameters"].size(); ++i) {
    const auto& p = j["parameters"][i];
    if (!p.contains("name") || !p.contains("value") || !p["value"].is_number()) {
      throw Error("'" + path + "': parameters[" + std::to_string(i) +
                  "] needs a name and a numeric value");
    }
    names.push_back(p["name"].get<std::string>());
    values[static_cast<Eigen::Index>(i)] = p["value"].get<double>();
  }
  options_used = j.value("options", nlohmann::json::object());
}

nlohmann::json base_parameters_to_json(const BaseParameters& base) {
  nlohmann::json list = nlohmann::json::array();
  for (int i = 0; i < base.rank; ++i) {
    list.push_back({{"name", base.names[i]}, {"expression", base.expressions[i]}});
  }
  return {{"rank", base.rank},
          {"base_parameters", list},
          {"unidentifiable", base.unidentifiable_names()},
          {"samples", base.samples}};
}

std::string base_parameters_text(const BaseParameters& base) {
  std::ostringstream s;
  s << base.rank << " base parameters (numerical Gautier-Khalil method, " << base.samples
    << " random states):\n";
  for (int i = 0; i < base.rank; ++i) s << "  " << base.expressions[i] << '\n';
  s << "no effect on the dynamics (unidentifiable):";
  for (const auto& n : base.unidentifiable_names()) s << ' ' << n;
  s << '\n';
  return s.str();
}

nlohmann::json validation_to_json(const Model& model, const ValidationResult& v) {
  nlohmann::json joints = nlohmann::json::array();
  for (int j = 0; j < model.dof(); ++j) {
    joints.push_back({{"name", model.joints[j].name},
                      {"rms", json_number(v.rms[j])},
                      {"relative_error", json_number(v.relative_error[j])}});
  }
  nlohmann::json choices = nlohmann::json::object();
  for (const auto& [key, value] : v.choices) choices[key] = value;
  return {{"joints", joints},
          {"relative_error", json_number(v.relative_error_all)},
          {"relative_error_all_rows", json_number(v.relative_error_all_rows)},
          {"samples", v.samples},
          {"rows", v.rows},
          {"rows_excluded_zero_velocity", v.rows_excluded},
          {"choices", choices},
          {"version", kVersion}};
}

std::string validation_table(const Model& model, const ValidationResult& v) {
  std::ostringstream s;
  for (int j = 0; j < model.dof(); ++j) {
    s << line("  %-12s torque RMS %.4g, relative error %.2f %%\n", model.joints[j].name.c_str(),
              v.rms[j], 100 * v.relative_error[j]);
  }
  s << line("all joints: relative error %.2f %% over %ld samples\n", 100 * v.relative_error_all,
            static_cast<long>(v.samples));
  if (v.rows_excluded > 0) {
    s << line(
        "  (%ld of %ld joint rows with |dq| below the zero-velocity threshold left out, as in "
        "identify; with them: %.2f %%; --zero-velocity 0 compares every row)\n",
        static_cast<long>(v.rows_excluded), static_cast<long>(v.rows + v.rows_excluded),
        100 * v.relative_error_all_rows);
  }
  return s.str();
}

namespace {

nlohmann::json statistics_json(const ErrorStatistics& e) {
  return {{"rms", json_number(e.rms)},
          {"max", json_number(e.max_abs)},
          {"mean", json_number(e.mean)},
          {"std", json_number(e.std)},
          {"skewness", json_number(e.skewness)},
          {"kurtosis", json_number(e.kurtosis)},
          {"ks_statistic", json_number(e.ks_statistic)},
          {"ks_p_value", json_number(e.ks_p_value)}};
}

}  // namespace

nlohmann::json simulation_validation_to_json(const Model& model, const SimulationValidation& v) {
  nlohmann::json joints = nlohmann::json::array();
  for (int j = 0; j < model.dof(); ++j) {
    joints.push_back({{"name", model.joints[j].name},
                      {"position", statistics_json(v.position[j])},
                      {"torque", statistics_json(v.torque[j])}});
  }
  return {{"mode", "simulation"},
          {"joints", joints},
          {"samples", v.position.empty() ? 0 : v.position[0].samples},
          {"version", kVersion}};
}

std::string simulation_validation_table(const Model& model, const SimulationValidation& v) {
  std::ostringstream s;
  s << "validation by simulation (errors measured - simulated, after the first period)\n";
  for (int j = 0; j < model.dof(); ++j) {
    s << line(
        "  %-12s position RMS %.4g max %.4g | torque RMS %.4g max %.4g, kurtosis %.3g, KS p %.3g\n",
        model.joints[j].name.c_str(), v.position[j].rms, v.position[j].max_abs, v.torque[j].rms,
        v.torque[j].max_abs, v.torque[j].kurtosis, v.torque[j].ks_p_value);
  }
  return s.str();
}

}  // namespace dynid
