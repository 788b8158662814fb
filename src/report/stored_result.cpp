#include "dynid/report/stored_result.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/identification/known_friction.hpp"

namespace dynid {

namespace {

// The friction set of a stored result: the command line's text options.friction, or the booleans a
// Python result records (dynid.identify's armature, viscous, coulomb, offset, asymmetric keywords).
ParameterLayout stored_layout(const ResultFileOptions& file) {
  const bool armature = file.get("armature", true);
  if (!file.used.contains("friction")) {
    const bool asymmetric = file.get("asymmetric", false);
    if (file.used.contains("viscous") || file.used.contains("coulomb") ||
        file.used.contains("offset") || file.used.contains("asymmetric")) {
      ParameterLayout layout;
      layout.armature = armature;
      layout.viscous = file.get("viscous", true) || asymmetric;
      layout.coulomb = file.get("coulomb", true) || asymmetric;
      layout.offset = file.get("offset", true);
      layout.asymmetric = asymmetric;
      return layout;
    }
  }
  return friction_layout(file.get("friction", std::string("viscous,coulomb,offset")), armature);
}

}  // namespace

Error stored_option_error(const UsageError& e, const std::string& path) {
  static const std::pair<const char*, const char*> kKeys[] = {
      {"--friction", "friction"},         {"--filter", "filter"},
      {"--cutoff", "cutoff_hz"},          {"--torque-offset", "torque_offset_s"},
      {"--time-shift", "time_shift_s"},   {"--zero-velocity", "zero_velocity"},
      {"--columns", "columns"},           {"--rate", "rate_hz"},
      {"--torque-scale", "torque_scale"}, {"--torque-bias", "torque_bias"}};
  std::string text = e.what();
  for (const auto& [flag, key] : kKeys) {
    if (text.rfind(flag, 0) == 0) {
      text = "options." + std::string(key) + text.substr(std::string(flag).size());
      break;
    }
  }
  return Error("'" + path + "': " + text +
               " (in the file; give the result.json of dynid identify "
               "unedited)");
}

StoredIdentifyOptions options_of_stored_result(const IdentifiedResultFile& identified,
                                               const std::string& path, int dof,
                                               const StoredOptionOverrides& overrides) {
  // The same friction set and signal processing as the identification that wrote the file.
  const ResultFileOptions file{identified.options, path};
  StoredIdentifyOptions out;
  IdentifyOptions& o = out.options;
  try {
    o.layout = stored_layout(file);
    if (identified.options.contains("filter") && identified.options["filter"].is_boolean()) {
      o.signal.filter = identified.options["filter"].get<bool>();  // a Python result
    } else {
      apply_filter_text(file.get("filter", std::string("auto")), o.signal);
    }
    // The cut-off identify used (its automatic choice included), not one chosen again on this run.
    if (overrides.cutoff) {
      o.signal.cutoff_hz = *overrides.cutoff;
    } else if (identified.cutoff_hz > 0.0) {
      o.signal.cutoff_hz = identified.cutoff_hz;
      o.signal.cutoff_source = "as identify used it";
      out.notes.push_back("cut-off as identify used it (stored in '" + path + "')");
    } else {
      o.signal.cutoff_hz = file.get("cutoff_hz", 0.0);
      o.signal.cutoff_source = "as given to identify";
    }
    o.signal.savitzky_golay = file.get("savitzky_golay", false);
    // time_shift_s since issue 26 item 7; older results have only torque_offset_s.
    if (overrides.time_shift) {
      o.signal.torque_time_offset = *overrides.time_shift;
    } else {
      o.signal.torque_time_offset = file.get("time_shift_s", file.get("torque_offset_s", 0.0));
      if (o.signal.torque_time_offset != 0.0)
        out.notes.push_back("--time-shift as given to identify (stored in '" + path + "')");
    }
    o.signal.filter_coulomb_columns = file.get("filter_coulomb_columns", false);
    // The Coulomb law identify used, so that rest is predicted as it was fitted (issue 25 item 9).
    if (static_cast<int>(identified.coulomb_width.size()) == dof) {
      o.signal.coulomb_width = identified.coulomb_width;
      o.signal.coulomb_width_source = "as identify used them";
    } else {
      o.signal.coulomb_width_fraction = 0.0;  // a file written before the law was stored
    }
    // The rows left out are those below the thresholds identify used (stored in the result), not
    // thresholds recomputed from this run.
    if (!overrides.zero_velocity.empty()) {
      o.signal.zero_velocity = overrides.zero_velocity;
    } else if (static_cast<int>(identified.zero_velocity_threshold.size()) == dof) {
      o.signal.zero_velocity = identified.zero_velocity_threshold;
      o.signal.zero_velocity_source = "as identify used them";
      if (*std::max_element(o.signal.zero_velocity.begin(), o.signal.zero_velocity.end()) > 0.0) {
        out.notes.push_back("zero-velocity thresholds as identify used them (stored in '" + path +
                            "')");
      }
    } else {
      o.signal.zero_velocity = file.get("zero_velocity", std::vector<double>{});
      o.signal.zero_velocity_source = "as given to identify";
    }
    // How identify read its run: a log of the same recorder is read the same way (a different
    // rename silently compares other columns).
    if (!overrides.columns_given) {
      out.columns = parse_column_mapping(file.get("columns", std::string()));
      if (!out.columns.empty())
        out.notes.push_back("--columns as given to identify (stored in '" + path + "')");
    }
    if (!overrides.rate_given) {
      out.rate_hz = file.get("rate_hz", 0.0);
      if (!(out.rate_hz >= 0.0) || !std::isfinite(out.rate_hz))
        throw UsageError("--rate " + short_number(out.rate_hz) + " is not a sample rate in Hz");
    }
    if (!overrides.torque_bias_given) {
      out.torque_bias = parse_torque_bias(file.get("torque_bias", std::string()));
      if (!out.torque_bias.empty())
        out.notes.push_back("--torque-bias as given to identify (stored in '" + path + "')");
    }
    if (!overrides.topic_given) {
      out.topic = file.get("topic", std::string());
      if (!out.topic.empty())
        out.notes.push_back("--topic as given to identify (stored in '" + path + "')");
    }
  } catch (const UsageError& e) {
    throw stored_option_error(e, path);
  }
  if (!overrides.torque_scale_given) {
    out.torque_scale = file.get("torque_scale", std::vector<double>{});
    if (!out.torque_scale.empty()) {
      out.notes.push_back("--torque-scale as given to identify (stored in '" + path + "')");
    }
  }
  return out;
}

void StoredIdentifyOptions::apply_to(RunFileOptions& file) const {
  if (!columns.empty()) file.columns = columns;
  if (rate_hz > 0.0) {
    file.rate_hz = rate_hz;
    file.rate_given = false;
  }
  if (!torque_scale.empty()) file.torque_scale = torque_scale;
  if (!torque_bias.empty()) file.torque_bias = torque_bias;
  if (!topic.empty()) file.topic = topic;
}

void add_stored_known_friction(const IdentifiedResultFile& identified, const std::string& path,
                               const Model& model, std::vector<std::string>& names,
                               Eigen::VectorXd& values, IdentifyOptions& options) {
  const auto it = identified.options.find("known_friction");
  if (it == identified.options.end()) return;
  std::vector<std::string> known_names;
  std::vector<double> known_values;
  try {
    for (const auto& p : *it) {
      known_names.push_back(p.at("name").get<std::string>());
      known_values.push_back(p.at("value").get<double>());
    }
  } catch (const nlohmann::json::exception&) {
    throw Error("'" + path +
                "': options.known_friction must list {name, value}; give the result of "
                "identify --friction-known unedited");
  }
  KnownFriction known;
  add_known_friction(known, model, known_names,
                     Eigen::Map<const Eigen::VectorXd>(
                         known_values.data(), static_cast<Eigen::Index>(known_values.size())),
                     path);
  append_known_friction(known, names, values, options.layout);
}

CompletedModel completed_model_of_result(const Model& model, const IdentifiedResultFile& identified,
                                         const std::string& path,
                                         const ModelCompletionOptions& completion) {
  IdentifyOptions options;
  try {
    options.layout = stored_layout(ResultFileOptions{identified.options, path});
  } catch (const UsageError& e) {
    throw stored_option_error(e, path);
  }
  std::vector<std::string> names = identified.names;
  Eigen::VectorXd values = identified.values;
  add_stored_known_friction(identified, path, model, names, values, options);
  return complete_identified_model(model, names, values, identified.std_devs,
                                   identified.not_excited, identified.data_regrouping,
                                   identified.covariance, options, completion);
}

ParameterCompletion nominal_completion_of_result(const Model& model,
                                                 const IdentifiedResultFile& identified,
                                                 const std::string& path) {
  ParameterCompletion out;
  if (identified.not_excited.empty()) return out;
  ModelCompletionOptions only_not_excited;
  only_not_excited.max_relative_std = 0.0;
  const CompletedModel c = completed_model_of_result(model, identified, path, only_not_excited);
  out.names = c.names;
  out.values = c.values;
  return out;
}

void add_stored_friction_compensation(const Model& model, const IdentifiedResultFile& identified,
                                      const std::string& path, int joint,
                                      FrictionExperimentOptions& options) {
  if (identified.experiment.empty()) return;
  const std::string jn = std::to_string(joint + 1);
  if (identified.experiment != "gravity" && identified.experiment != "decoupled") {
    throw Error("'" + path + "' is a --model " + identified.experiment +
                " result; compensate a friction experiment with a result of identify (the "
                "differential or integral model), --model gravity or --model decoupled");
  }
  if (identified.experiment_joint != joint + 1) {
    throw Error("'" + path + "' is the " + identified.experiment + " result of joint " +
                std::to_string(identified.experiment_joint) + "; give the one of joint " + jn);
  }
  const auto value = [&](const std::string& name) {
    const auto it = std::find(identified.names.begin(), identified.names.end(), name);
    if (it == identified.names.end())
      throw Error("'" + path + "' has no parameter '" + name +
                  "'; write it with dynid identify "
                  "--model " +
                  identified.experiment);
    return identified.values[it - identified.names.begin()];
  };
  const bool sinusoid = std::find(identified.names.begin(), identified.names.end(), "k" + jn) !=
                        identified.names.end();
  if (sinusoid) {
    options.gravity = JointGravityModel::sinusoid(joint, value("k" + jn), value("qoff" + jn));
  } else {
    options.gravity = JointGravityModel::poses(model, joint, identified.names, identified.values);
  }
  if (identified.experiment == "decoupled") options.equivalent_inertia = value("M" + jn);
}

nlohmann::json parameter_sources_json(const CompletedModel& c) {
  return {{"identified", c.identified},
          {"nominal_not_excited", c.nominal_not_excited},
          {"nominal_badly_determined", c.nominal_badly_determined},
          {"max_shift_sigma", c.max_shift_sigma}};
}

}  // namespace dynid
