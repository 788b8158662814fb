#include "dynid/report/experiment_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "dynid/common/message.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/version.hpp"

namespace dynid {

namespace {

nlohmann::json numbers(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(json_number(v[i]));
  return a;
}

nlohmann::json parameter(const std::string& name, double value, double std, double critical) {
  return {{"name", name},
          {"value", json_number(value)},
          {"std", json_number(std)},
          {"relative_std_percent",
           json_number(value != 0.0 ? 100.0 * std / std::abs(value) : INFINITY)},
          {"ci_low", json_number(value - critical * std)},
          {"ci_high", json_number(value + critical * std)}};
}

// Parameters i of an estimate, with their intervals as the estimator computed them.
void add_estimated(nlohmann::json& params, const std::vector<std::string>& names, const Estimate& e,
                   Eigen::Index from, Eigen::Index to) {
  for (Eigen::Index i = from; i < to; ++i) {
    params.push_back({{"name", names[static_cast<size_t>(i)]},
                      {"value", json_number(e.x[i])},
                      {"std", json_number(e.std_dev[i])},
                      {"relative_std_percent", json_number(e.relative_std_percent[i])},
                      {"ci_low", json_number(e.ci_lower[i])},
                      {"ci_high", json_number(e.ci_upper[i])}});
    if (e.std_dev_white.size() == e.x.size())
      params.back()["std_white"] = json_number(e.std_dev_white[i]);
  }
}

nlohmann::json common(const Model& model, const char* kind, int joint, nlohmann::json params,
                      const Estimate& e,
                      const std::vector<std::pair<std::string, std::string>>& choices,
                      const std::vector<std::string>& warnings, const nlohmann::json& options) {
  nlohmann::json c = nlohmann::json::object();
  for (const auto& [k, v] : choices) c[k] = v;
  c["model"] = kind;
  std::vector<std::string> joints;
  for (const Joint& j : model.joints) joints.push_back(j.name);
  return {
      {"model",
       {{"name", model.name}, {"source", model.source}, {"dof", model.dof()}, {"joints", joints}}},
      {"experiment", kind},
      {"joint", joint + 1},
      {"parameters", std::move(params)},
      {"confidence_level", e.confidence_level},
      {"estimator", to_string(e.summary.estimator)},
      {"warnings", warnings},
      {"choices", c},
      {"options", options},
      {"version", kVersion}};
}

// Half-width multiplier of the estimate's intervals (the HAC fixed-b value).
double critical(const Estimate& e) {
  return e.critical_value > 0.0 ? e.critical_value : e.t_quantile;
}

// `slopes` of a gravity result: per slope its name, cruise velocity, offset and rows.
template <typename Result>
nlohmann::json slopes_json(const Result& r) {
  nlohmann::json slopes = nlohmann::json::array();
  for (size_t s = 0; s < r.slope_names.size(); ++s) {
    slopes.push_back({{"name", r.slope_names[s]},
                      {"velocity", json_number(r.slope_velocity[s])},
                      {"offset", json_number(r.offset[s])},
                      {"offset_std", json_number(r.offset_std[s])},
                      {"rows", r.slope_rows[s]}});
  }
  return slopes;
}

}  // namespace

nlohmann::json gravity_experiment_to_json(const Model& model, const GravityExperimentResult& r,
                                          const nlohmann::json& options_used) {
  const std::string j = std::to_string(r.joint + 1);
  const double c = critical(r.estimate);
  nlohmann::json params = nlohmann::json::array();
  params.push_back(parameter("k" + j, r.k, r.k_std, c));
  params.push_back(parameter("qoff" + j, r.q_off, r.q_off_std, c));
  nlohmann::json out = common(model, "gravity", r.joint, std::move(params), r.estimate, r.choices,
                              r.warnings, options_used);
  out["slopes"] = slopes_json(r);
  out["rows"] = r.rows;
  out["relative_error"] = json_number(r.relative_error);
  out["residual_rms"] = json_number(r.residual_rms);
  out["fit"] = {{"run", r.sample_run},
                {"q", numbers(r.sample_q)},
                {"tau", numbers(r.sample_tau)},
                {"fitted", numbers(r.sample_fitted)}};
  return out;
}

nlohmann::json gravity_poses_to_json(const Model& model, const GravityPosesResult& r,
                                     const nlohmann::json& options_used) {
  nlohmann::json params = nlohmann::json::array();
  const auto rg = static_cast<Eigen::Index>(r.names.size());
  add_estimated(params, r.names, r.estimate, 0, rg);
  nlohmann::json out = common(model, "gravity", r.joint, std::move(params), r.estimate, r.choices,
                              r.warnings, options_used);
  nlohmann::json base = nlohmann::json::array();
  for (size_t i = 0; i < r.names.size(); ++i)
    base.push_back({{"name", r.names[i]}, {"expression", r.expressions[i]}});
  out["base_parameters"] = base;
  nlohmann::json poses = nlohmann::json::array();
  for (size_t p = 0; p < r.k.size(); ++p) {
    poses.push_back({{"pose", numbers(r.pose[p])},
                     {"k", json_number(r.k[p])},
                     {"k_std", json_number(r.k_std[p])},
                     {"k_ci_half_width", json_number(r.k_ci_half_width[p])},
                     {"qoff", json_number(r.q_off[p])},
                     {"qoff_std", json_number(r.q_off_std[p])},
                     {"qoff_ci_half_width", json_number(r.q_off_ci_half_width[p])}});
  }
  out["poses"] = poses;
  out["slopes"] = slopes_json(r);
  out["rows"] = r.rows;
  out["relative_error"] = json_number(r.relative_error);
  out["residual_rms"] = json_number(r.residual_rms);
  return out;
}

nlohmann::json friction_experiment_to_json(const Model& model, const FrictionExperimentResult& r,
                                           const nlohmann::json& options_used) {
  nlohmann::json params = nlohmann::json::array();
  add_estimated(params, r.names, r.estimate, 0, 4);
  nlohmann::json out = common(model, "friction", r.joint, std::move(params), r.estimate, r.choices,
                              r.warnings, options_used);
  out["rows"] = r.rows;
  out["rows_left_out"] = r.rows_left_out;
  out["zero_velocity_threshold"] = json_number(r.zero_velocity_threshold);
  out["relative_error"] = json_number(r.relative_error);
  out["residual_rms"] = json_number(r.residual_rms);
  out["curve"] = {{"velocity", numbers(r.curve_velocity)}, {"torque", numbers(r.curve_torque)}};
  out["fit"] = {{"run", r.sample_run},
                {"t", numbers(r.sample_t)},
                {"dq", numbers(r.sample_dq)},
                {"tau", numbers(r.sample_tau)},
                {"fitted", numbers(r.sample_fitted)}};
  return out;
}

nlohmann::json decoupled_model_to_json(const Model& model, const DecoupledJointResult& r,
                                       const nlohmann::json& options_used) {
  const std::string j = std::to_string(r.joint + 1);
  const double c = critical(r.estimate);
  nlohmann::json params = nlohmann::json::array();
  add_estimated(params, r.names, r.estimate, 0, 1);
  params.push_back(parameter("k" + j, r.k, r.k_std, c));
  params.push_back(parameter("qoff" + j, r.q_off, r.q_off_std, c));
  add_estimated(params, r.names, r.estimate, 3, 7);
  nlohmann::json out = common(model, "decoupled", r.joint, std::move(params), r.estimate, r.choices,
                              r.warnings, options_used);
  out["rows"] = r.rows;
  out["relative_error"] = json_number(r.relative_error);
  out["held_span"] = numbers(r.held_span);
  out["coupling_ratio"] = numbers(r.coupling_ratio);
  return out;
}

void physical_parameters_to_json(const PhysicalFit& fit, double relative_error,
                                 double relative_error_unconstrained, nlohmann::json& result,
                                 const std::vector<std::string>& warnings) {
  nlohmann::json list = nlohmann::json::array();
  for (size_t i = 0; i < fit.names.size(); ++i) {
    list.push_back(
        {{"name", fit.names[i]}, {"value", json_number(fit.theta[static_cast<Eigen::Index>(i)])}});
  }
  result["standard_parameters"] = list;
  result["physically_consistent"] = fit.consistent;
  result["physical"] = {
      {"mahalanobis", json_number(fit.mahalanobis)},
      {"distance_sigma", json_number(fit.mahalanobis)},
      {"chi2_limit", json_number(fit.chi2_limit)},
      {"within_limit", fit.within_limit},
      {"nominal_distance", json_number(fit.nominal_distance)},
      {"converged", fit.converged},
      {"iterations", fit.iterations},
      {"relative_error", json_number(relative_error)},
      {"relative_error_unconstrained", json_number(relative_error_unconstrained)},
      {"min_pseudo_inertia_eigenvalue", numbers(fit.min_pseudo_inertia_eigenvalue)},
      {"warnings", warnings}};
  if (!result.contains("warnings") || !result["warnings"].is_array())
    result["warnings"] = nlohmann::json::array();
  for (const std::string& w : warnings) result["warnings"].push_back(w);
}

std::string physical_parameters_text(const PhysicalFit& fit, double relative_error,
                                     double relative_error_unconstrained) {
  char buf[400];
  std::snprintf(
      buf, sizeof(buf),
      "physically consistent parameters: %s, %.3g sigma from the estimate (limit %.3g%s), "
      "torque error %.2f %% against %.2f %% unconstrained%s\n",
      fit.consistent ? "found" : "NOT found", fit.mahalanobis, fit.chi2_limit,
      fit.within_limit ? "" : ", exceeded", 100.0 * relative_error,
      100.0 * relative_error_unconstrained,
      fit.converged ? "" : " (the fit stopped at its iteration limit)");
  return buf;
}

std::string experiment_table(const nlohmann::json& result) {
  std::ostringstream s;
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%-10s %14s %12s %9s   %.4g%% confidence interval\n", "parameter",
                "value", "std", "%std", 100.0 * result.value("confidence_level", 0.0));
  s << buf;
  auto num = [](const nlohmann::json& v) { return v.is_number() ? v.get<double>() : NAN; };
  for (const auto& p : result["parameters"]) {
    std::snprintf(buf, sizeof(buf), "%-10s %14.6g %12.4g %9.2f   [%.6g, %.6g]\n",
                  p["name"].get<std::string>().c_str(), num(p["value"]), num(p["std"]),
                  num(p["relative_std_percent"]), num(p["ci_low"]), num(p["ci_high"]));
    s << buf;
  }
  if (result.contains("relative_error")) {
    std::snprintf(buf, sizeof(buf),
                  "\n%s experiment of joint %d: %ld samples, relative error %.2f %%\n",
                  result["experiment"].get<std::string>().c_str(), result["joint"].get<int>(),
                  result.value("rows", 0L), 100.0 * num(result["relative_error"]));
    s << buf;
  }
  for (const auto& w : result["warnings"])
    s << "warning: " << one_line(w.get<std::string>()) << '\n';
  return s.str();
}

}  // namespace dynid
