#include "dynid/report/identification_report.hpp"
#include "dynid/identification/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/version.hpp"

namespace dynid {

namespace {

// The name a parameter is reported under (IdentificationResult::labels, else its base name).
const std::string& reported_name(const IdentificationResult& r, size_t i) {
  return r.labels.size() == r.names.size() ? r.labels[i] : r.names[i];
}

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

// Width of the joint-name column of a table: the longest name, at least `minimum`.
int name_width(const Model& model, int minimum) {
  int w = minimum;
  for (const Joint& j : model.joints) w = std::max(w, static_cast<int>(j.name.size()));
  return w;
}

// True for a base parameter that is one standard parameter, unregrouped ("XY2 = XY2").
bool is_identity(const std::string& expression) {
  const auto eq = expression.find(" = ");
  return eq != std::string::npos && expression.substr(0, eq) == expression.substr(eq + 3);
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

// The array `key` of a result file as non-negative finite numbers; empty when absent.
std::vector<double> non_negative_numbers(const nlohmann::json& j, const char* key,
                                         const std::string& path) {
  std::vector<double> out;
  const auto it = j.find(key);
  if (it == j.end() || !it->is_array()) return out;
  for (const auto& x : *it) {
    if (!x.is_number() || !std::isfinite(x.get<double>()) || x.get<double>() < 0.0) {
      throw Error("'" + path + "': " + key +
                  " must be non-negative numbers; write the file with dynid identify");
    }
    out.push_back(x.get<double>());
  }
  return out;
}

}  // namespace

nlohmann::json identification_to_json(const Model& model, const IdentificationResult& r,
                                      const nlohmann::json& options_used) {
  const Estimate& e = r.estimate;
  nlohmann::json params = nlohmann::json::array();
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    params.push_back({{"name", reported_name(r, i)},
                      {"value", json_number(e.x[k])},
                      {"std", json_number(e.std_dev[k])},
                      {"relative_std_percent", json_number(e.relative_std_percent[k])},
                      {"ci_low", json_number(e.ci_lower[k])},
                      {"ci_high", json_number(e.ci_upper[k])},
                      {"expression", r.expressions[i]},
                      {"unit", parameter_unit(model, r.names[i])}});
    // A data regrouping's name (Fc2R) is what the user reads; the base parameter it extends is
    // what validate, export and the completion look up.
    if (reported_name(r, i) != r.names[i]) params.back()["base_name"] = r.names[i];
    // The nominal (model file's) value beside the estimate; null where the model has none.
    params.back()["nominal"] =
        i < r.nominal.size() && r.nominal[i] ? json_number(*r.nominal[i]) : nlohmann::json(nullptr);
    if (e.std_dev_white.size() == e.x.size()) {
      params.back()["std_white"] = json_number(e.std_dev_white[k]);
      params.back()["ci_white_low"] = json_number(e.ci_lower_white[k]);
      params.back()["ci_white_high"] = json_number(e.ci_upper_white[k]);
    }
  }
  nlohmann::json choices = nlohmann::json::object();
  for (const auto& [k, v] : r.choices) choices[k] = v;
  nlohmann::json lockstep = nlohmann::json::array();
  for (const LockstepJoints& pair : r.lockstep) {
    lockstep.push_back({{"joints",
                         {model.joints[static_cast<size_t>(pair.first)].name,
                          model.joints[static_cast<size_t>(pair.second)].name}},
                        {"correlation", json_number(pair.correlation)},
                        {"undetermined", pair.undetermined}});
  }
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& run : r.runs) {
    runs.push_back({{"file", run.file},
                    {"samples", run.samples},
                    {"rows", run.rows},
                    {"relative_error", json_number(run.relative_error)}});
  }
  // Present only with RLS; no nulls in results (holds is false when the condition never holds).
  nlohmann::json excitation = nlohmann::json::object();
  if (r.has_excitation) {
    excitation = {{"window", r.excitation.window},
                  {"windows", r.excitation.windows},
                  {"min_eigenvalue", json_number(r.excitation.min_eigenvalue)},
                  {"max_eigenvalue", json_number(r.excitation.max_eigenvalue)},
                  {"holds", std::isfinite(r.excitation.holds_from_t)}};
    if (std::isfinite(r.excitation.holds_from_t)) {
      excitation["holds_from_t"] = r.excitation.holds_from_t;
    }
  }
  // The covariance and the data regroupings let a later command fill undetermined parameters
  // (complete_identified_model) without the data.
  auto rows = [](const Eigen::MatrixXd& m) {
    nlohmann::json out = nlohmann::json::array();
    for (Eigen::Index i = 0; i < m.rows(); ++i) out.push_back(numbers(m.row(i).transpose()));
    return out;
  };
  nlohmann::json out = {{"model",
                         {{"name", model.name},
                          {"source", model.source},
                          {"dof", model.dof()},
                          {"joints", joint_names(model)}}},
                        {"locked_joints", locked_joints_to_json(model)},
                        {"parameters", params},
                        {"covariance_matrix", rows(e.covariance)},
                        {"data_regrouping",
                         r.not_excited.empty() ? nlohmann::json::array() : rows(r.data_regrouping)},
                        {"confidence_level", e.confidence_level},
                        {"rank", r.rank},
                        {"data_rank", r.data_rank},
                        {"not_excited", r.not_excited},
                        {"data_regrouped", r.data_regrouped},
                        {"lockstep", lockstep},
                        {"runs", runs},
                        {"excitation", excitation},
                        {"condition_number", json_number(r.condition_number)},
                        {"samples", r.samples},
                        {"rows", r.rows},
                        {"residual_rms", numbers(r.residual_rms)},
                        {"joint_relative_error", numbers(r.joint_relative_error)},
                        {"residual_autocorrelation", numbers(r.residual_autocorrelation)},
                        {"relative_error", json_number(r.relative_error)},
                        {"zero_velocity_threshold", numbers(r.zero_velocity_threshold)},
                        {"coulomb_width", numbers(r.coulomb_width)},
                        {"residual_variance", json_number(e.residual_variance)},
                        {"estimator", to_string(e.summary.estimator)},
                        {"unidentifiable", r.unidentifiable},
                        {"warnings", r.warnings},
                        {"choices", choices},
                        {"options", options_used},
                        {"version", kVersion}};
  if (!r.interval_source.empty()) out["interval_source"] = r.interval_source;
  return out;
}

std::string identification_table(const Model& model, const IdentificationResult& r) {
  const Estimate& e = r.estimate;
  std::ostringstream s;
  int pw = 10;
  for (size_t i = 0; i < r.names.size(); ++i)
    pw = std::max(pw, static_cast<int>(reported_name(r, i).size()));
  s << line("%-*s %14s %12s %9s %14s   %-29s\n", pw, "parameter", "value", "std", "%std", "nominal",
            (line("%.4g", 100 * e.confidence_level) + "% confidence interval").c_str());
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    const std::string nominal =
        i < r.nominal.size() && r.nominal[i] ? line("%.6g", *r.nominal[i]) : "-";
    s << line("%-*s %14.6g %12.4g %9.2f %14s   [%.6g, %.6g]\n", pw, reported_name(r, i).c_str(),
              e.x[k], e.std_dev[k], e.relative_std_percent[k], nominal.c_str(), e.ci_lower[k],
              e.ci_upper[k]);
  }
  s << line(
      "\nrank %d, condition number %.4g, %ld samples, %ld equations, relative error %.2f %%\n",
      r.rank, r.condition_number, static_cast<long>(r.samples), static_cast<long>(r.rows),
      100 * r.relative_error);
  if (!r.not_excited.empty()) {
    s << "data rank " << r.data_rank << " < " << r.rank << "; not excited (not estimated):";
    for (const auto& name : r.not_excited) {
      if (std::find(r.data_regrouped.begin(), r.data_regrouped.end(), name) ==
          r.data_regrouped.end())
        s << ' ' << name;
    }
    if (!r.data_regrouped.empty()) {
      s << "; regrouped on these data (see the R parameters' expressions):";
      for (const auto& name : r.data_regrouped) s << ' ' << name;
    }
    s << '\n';
  }
  if (r.runs.size() > 1) {
    for (size_t i = 0; i < r.runs.size(); ++i) {
      s << line("  run %zu %s: %ld samples, %ld equations, relative error %.2f %%\n", i + 1,
                one_line(r.runs[i].file).c_str(), static_cast<long>(r.runs[i].samples),
                static_cast<long>(r.runs[i].rows), 100 * r.runs[i].relative_error);
    }
  }
  const int w = name_width(model, 12);
  if (r.residual_rms.size() == model.dof()) {
    for (int j = 0; j < model.dof(); ++j) {
      s << line("  %-*s residual RMS %.4g, relative error %.2f %%\n", w,
                model.joints[j].name.c_str(), r.residual_rms[j], 100 * r.joint_relative_error[j]);
    }
  } else {
    // The integral model's equations are one group of energy rows.
    for (Eigen::Index g = 0; g < r.residual_rms.size(); ++g) {
      s << line("  energy equations: residual RMS %.4g J, relative error %.2f %%\n",
                r.residual_rms[g], 100 * r.joint_relative_error[g]);
    }
  }
  for (const auto& w : r.warnings) s << "warning: " << one_line(w) << '\n';
  return s.str();
}

namespace {
// `std` per parameter, `covariance_matrix` and `data_regrouping` (optional: hand-written files
// and files written before they were stored have none; numbers that do not fit are an error).
void read_completion_data(const nlohmann::json& j, const std::string& path,
                          IdentifiedResultFile& out) {
  const auto n = static_cast<Eigen::Index>(out.names.size());
  out.std_devs = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto& p = j["parameters"][static_cast<size_t>(i)];
    if (p.contains("std") && p["std"].is_number()) out.std_devs[i] = p["std"].get<double>();
  }
  auto matrix = [&](const char* key, Eigen::Index rows, Eigen::Index cols) {
    const auto it = j.find(key);
    if (it == j.end()) return Eigen::MatrixXd();
    Eigen::MatrixXd m(rows, cols);
    bool ok = it->is_array() && static_cast<Eigen::Index>(it->size()) == rows;
    bool finite = true;  // null (an infinite σ) leaves the matrix out, not the file
    for (Eigen::Index r = 0; ok && r < rows; ++r) {
      const auto& row = (*it)[static_cast<size_t>(r)];
      ok = row.is_array() && static_cast<Eigen::Index>(row.size()) == cols;
      for (Eigen::Index c = 0; ok && c < cols; ++c) {
        const auto& x = row[static_cast<size_t>(c)];
        ok = x.is_number() || x.is_null();
        finite = finite && x.is_number() && std::isfinite(x.get<double>());
        if (finite) m(r, c) = x.get<double>();
      }
    }
    if (ok && !finite) return Eigen::MatrixXd();
    if (!ok) {
      throw Error("'" + path + "': " + key + " must be " + std::to_string(rows) + " rows of " +
                  std::to_string(cols) +
                  " finite numbers; give the result.json of dynid "
                  "identify unedited");
    }
    return m;
  };
  out.covariance = matrix("covariance_matrix", n, n);
  const auto ne = static_cast<Eigen::Index>(out.not_excited.size());
  if (ne > 0) out.data_regrouping = matrix("data_regrouping", n, ne);
}
}  // namespace

IdentifiedResultFile read_identification_result(const std::string& path) {
  std::string text;
  try {
    text = read_regular_file(path, kMaxResultFileBytes, "parameter file");
  } catch (const Error& e) {
    throw Error(std::string(e.what()) + " (the result.json of dynid identify)");
  }
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& ex) {
    throw Error("'" + path + "' is not valid JSON (" + one_line(ex.what()) + ")");
  }
  return identification_result_from_json(j, path);
}

IdentifiedResultFile identification_result_from_json(const nlohmann::json& j,
                                                     const std::string& path) {
  if (!j.is_object() || !j.contains("parameters") || !j["parameters"].is_array()) {
    throw Error("'" + path + "' has no 'parameters' list; give the result.json of dynid identify");
  }
  IdentifiedResultFile out;
  out.values.resize(static_cast<Eigen::Index>(j["parameters"].size()));
  for (size_t i = 0; i < j["parameters"].size(); ++i) {
    const auto& p = j["parameters"][i];
    if (!p.is_object() || !p.contains("name") || !p["name"].is_string() || !p.contains("value") ||
        !p["value"].is_number()) {
      throw Error("'" + path + "': parameters[" + std::to_string(i) +
                  "] needs a string name and a numeric value");
    }
    // base_name: the base parameter a data regrouping (name Fc2R) extends, as identify writes it.
    const bool based = p.contains("base_name") && p["base_name"].is_string();
    out.names.push_back(based ? p["base_name"].get<std::string>() : p["name"].get<std::string>());
    out.values[static_cast<Eigen::Index>(i)] = p["value"].get<double>();
    if (!std::isfinite(out.values[static_cast<Eigen::Index>(i)])) {
      throw Error("'" + path + "': parameters[" + std::to_string(i) +
                  "].value overflows a double; give the result.json of dynid identify");
    }
  }
  const auto options = j.find("options");
  if (options != j.end() && !options->is_object()) {
    throw Error("'" + path + "': 'options' must be an object (as dynid identify writes it)");
  }
  out.options = options != j.end() ? *options : nlohmann::json::object();
  const auto model = j.find("model");
  if (model != j.end() && model->is_object()) {
    if (model->contains("name") && (*model)["name"].is_string()) {
      out.robot = (*model)["name"].get<std::string>();
    }
    if (model->contains("joints") && (*model)["joints"].is_array()) {
      for (const auto& name : (*model)["joints"]) {
        if (name.is_string()) out.joints.push_back(name.get<std::string>());
      }
    }
  }
  out.locked_joints = locked_joints_from_json(j, path);
  out.zero_velocity_threshold = non_negative_numbers(j, "zero_velocity_threshold", path);
  out.coulomb_width = non_negative_numbers(j, "coulomb_width", path);
  const auto not_excited = j.find("not_excited");
  if (not_excited != j.end()) {
    if (!not_excited->is_array()) {
      throw Error("'" + path +
                  "': not_excited must be a list of parameter names (as dynid "
                  "identify writes it)");
    }
    for (const auto& name : *not_excited) {
      if (!name.is_string()) {
        throw Error("'" + path +
                    "': not_excited must be a list of parameter names (as dynid "
                    "identify writes it)");
      }
      out.not_excited.push_back(name.get<std::string>());
    }
  }
  read_completion_data(j, path, out);
  const auto choices = j.find("choices");
  if (choices != j.end() && choices->is_object() && choices->contains("cutoff_hz")) {
    const auto& c = (*choices)["cutoff_hz"];
    try {
      out.cutoff_hz = c.is_number() ? c.get<double>() : std::stod(c.get<std::string>());
    } catch (const std::exception&) {
      out.cutoff_hz = -1.0;
    }
    if (!(out.cutoff_hz > 0.0) || !std::isfinite(out.cutoff_hz)) {
      throw Error("'" + path +
                  "': choices.cutoff_hz must be a positive number of Hz; write the file with "
                  "dynid identify");
    }
  }
  const auto experiment = j.find("experiment");
  if (experiment != j.end() && experiment->is_string()) {
    out.experiment = experiment->get<std::string>();
    const auto joint = j.find("joint");
    if (joint == j.end() || !joint->is_number_integer() || joint->get<int>() < 1) {
      throw Error("'" + path +
                  "': an experiment result needs its 1-based 'joint'; write the file "
                  "with dynid identify --model " +
                  out.experiment);
    }
    out.experiment_joint = joint->get<int>();
  }
  return out;
}

void read_identified_parameters(const std::string& path, std::vector<std::string>& names,
                                Eigen::VectorXd& values, nlohmann::json& options_used) {
  IdentifiedResultFile file = read_identification_result(path);
  names = std::move(file.names);
  values = std::move(file.values);
  options_used = std::move(file.options);
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
  std::string alone;
  for (int i = 0; i < base.rank; ++i) {
    if (is_identity(base.expressions[i])) {
      alone += ' ' + base.names[i];
    } else {
      s << "  " << base.expressions[i] << '\n';
    }
  }
  if (!alone.empty()) s << "identifiable alone (not regrouped):" << alone << '\n';
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
                      {"relative_error", json_number(v.relative_error[j])},
                      {"relative_error_moving", json_number(v.relative_error[j])},
                      {"rms_all_rows", json_number(v.rms_all_rows[j])},
                      {"relative_error_all_rows", json_number(v.relative_error_all_rows_joint[j])},
                      {"rows_left_out", v.joint_rows_excluded[j]}});
  }
  nlohmann::json choices = nlohmann::json::object();
  for (const auto& [key, value] : v.choices) choices[key] = value;
  // relative_error is the moving-rows figure (its name before issue 26 item 6, kept for scripts);
  // relative_error_moving says so, relative_error_all_rows is the headline.
  return {{"joints", joints},
          {"relative_error", json_number(v.relative_error_all)},
          {"relative_error_moving", json_number(v.relative_error_all)},
          {"relative_error_all_rows", json_number(v.relative_error_all_rows)},
          {"samples", v.samples},
          {"rows", v.rows},
          {"rows_excluded_zero_velocity", v.rows_excluded},
          {"rows_left_out",
           {{"rule",
             "rows of joint j with |dq_j| < zero_velocity_threshold[j] are left out of "
             "relative_error_moving (= relative_error), rms and joints[].relative_error_moving "
             "(Coulomb friction: sign(dq) is "
             "undefined there), as identify left them out of the fit; the *_all_rows figures "
             "keep every row"},
            {"zero_velocity_threshold", numbers(v.zero_velocity_threshold)},
            {"rows", v.rows_excluded}}},
          {"rows_still",
           {{"rule",
             "rows of joint j with |dq_j| < threshold[j] = max(coulomb_width[j], 3 x the "
             "velocity noise std) count as still: the joint is inside the Coulomb law's "
             "transition band (its term below 68 % of Fc) or cannot be told from rest; they are "
             "predicted with the same smooth Coulomb law identify fitted and kept in every "
             "figure above"},
            {"threshold", numbers(v.still_threshold)},
            {"rows", numbers(v.joint_rows_still.cast<double>())},
            {"relative_error_still_rows", json_number(v.relative_error_still_rows)},
            {"relative_error_moving_rows", json_number(v.relative_error_moving_rows)}}},
          {"completed", v.completed},
          {"filled_share", json_number(v.filled_share)},
          {"warnings", v.warnings},
          {"choices", choices},
          {"version", kVersion}};
}

std::string validation_table(const Model& model, const ValidationResult& v) {
  std::ostringstream s;
  const int w = name_width(model, 5);
  const long all = static_cast<long>(v.rows + v.rows_excluded);
  s << line("%-*s %12s %15s %21s %10s\n", w + 2, "joint", "RMS [N m]", "rel. error",
            "rel. error (moving)", "left out");
  for (int j = 0; j < model.dof(); ++j) {
    s << line("  %-*s %12.4g %13.2f %% %19.2f %% %10d\n", w, model.joints[j].name.c_str(),
              v.rms_all_rows[j], 100 * v.relative_error_all_rows_joint[j],
              100 * v.relative_error[j], v.joint_rows_excluded[j]);
  }
  s << line("relative torque error over every row: %.2f %% (%ld samples, %ld joint rows)\n",
            100 * v.relative_error_all_rows, static_cast<long>(v.samples), all);
  if (v.rows_excluded > 0) {
    std::ostringstream t;
    t << v.zero_velocity_threshold.transpose();
    s << line(
        "relative torque error without near-still rows: %.2f %% (%ld of %ld joint rows with "
        "|dq_j| below [%s] left out, as identify left them out of the fit; --zero-velocity 0 "
        "keeps every row)\n",
        100 * v.relative_error_all, static_cast<long>(v.rows_excluded), all, t.str().c_str());
  }
  return s.str();
}

void write_validation_predictions(const std::string& path, const ValidationResult& v) {
  const JointRecord& r = v.processed.record;
  const Eigen::Index m = r.t.size();
  const Eigen::Index n = r.tau.cols();
  std::vector<std::string> columns = {"t"};
  Eigen::MatrixXd data(m, 1 + 4 * n);
  data.col(0) = r.t;
  for (Eigen::Index j = 0; j < n; ++j) {
    const std::string k = std::to_string(j + 1);
    for (const char* prefix : {"tau", "tau_pred", "residual", "left_out"}) {
      columns.push_back(prefix + k);
    }
    data.col(1 + 4 * j) = r.tau.col(j);
    data.col(2 + 4 * j) = v.predicted.col(j);
    data.col(3 + 4 * j) = r.tau.col(j) - v.predicted.col(j);
    const double threshold =
        j < v.zero_velocity_threshold.size() ? v.zero_velocity_threshold[j] : 0;
    data.col(4 + 4 * j) = (r.dq.col(j).array().abs() < threshold).cast<double>();
  }
  write_csv(path, columns, data);
}

void write_rls_history(const std::string& path, const IdentificationResult& r) {
  const Eigen::Index rows = r.history_x.rows(), p = r.history_x.cols();
  if (rows == 0 || static_cast<Eigen::Index>(r.names.size()) != p) {
    throw Error("no RLS history to write to '" + path + "'; identify with --estimator rls");
  }
  // σ after k equations needs k > p (residual degrees of freedom): start there.
  Eigen::Index first = 0;
  while (first < rows && !r.history_std.row(first).allFinite()) ++first;
  if (first == rows) {
    throw Error("the RLS history has no equation with a finite sigma; '" + path +
                "' not written (more equations than parameters are needed)");
  }
  std::vector<std::string> columns = {"t"};
  Eigen::MatrixXd data(rows - first, 1 + 2 * p);
  data.col(0) = r.history_t.segment(first, rows - first);
  for (Eigen::Index c = 0; c < p; ++c) {
    columns.push_back(r.names[static_cast<size_t>(c)]);
    columns.push_back(r.names[static_cast<size_t>(c)] + "_std");
    data.col(1 + 2 * c) = r.history_x.col(c).segment(first, rows - first);
    data.col(2 + 2 * c) = r.history_std.col(c).segment(first, rows - first);
  }
  write_csv(path, columns, data);
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
