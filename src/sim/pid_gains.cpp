#include "dynid/sim/pid_gains.hpp"

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/json_writer.hpp"

namespace dynid {

namespace {

Eigen::VectorXd read_gain_list(const YAML::Node& doc, const char* key, const std::string& path,
                               int n) {
  const YAML::Node node = doc[key];
  if (!node)
    throw Error("gains file " + path + " has no '" + key +
                "': give kp, ki and kd, one value per joint");
  if (!node.IsSequence() || static_cast<int>(node.size()) != n)
    throw Error("gains file " + path + ": '" + key + "' must be a list of " + std::to_string(n) +
                " values (one per joint), got " +
                (node.IsSequence() ? std::to_string(node.size()) + " values" : "a single value"));
  Eigen::VectorXd v(n);
  for (int j = 0; j < n; ++j) {
    double x = 0.0;
    try {
      x = node[j].as<double>();
    } catch (const YAML::Exception&) {
      throw Error("gains file " + path + ": " + key + "[" + std::to_string(j + 1) +
                  "] is not a number");
    }
    if (!std::isfinite(x) || x < 0.0)
      throw Error("gains file " + path + ": " + key + "[" + std::to_string(j + 1) +
                  "] = " + short_number(x) + " must be a finite number >= 0");
    v[j] = x;
  }
  return v;
}

}  // namespace

PidGains read_pid_gains(const std::string& path, const Model& model) {
  require_regular_file(path, "gains file");
  YAML::Node doc;
  try {
    doc = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw Error("cannot read gains file " + path + ": check the path");
  } catch (const YAML::Exception& e) {
    throw Error("gains file " + path + " is not valid YAML (line " +
                std::to_string(e.mark.line + 1) + "): " + one_line(e.msg));
  }
  if (!doc.IsMap())
    throw Error("gains file " + path +
                " must be a mapping with kp, ki, kd lists, e.g. kp: [400, 120]");
  static const std::set<std::string> kKnown = {"kp",
                                               "ki",
                                               "kd",
                                               "controller",
                                               "joints",
                                               "sample_time",
                                               "derivative_filter_time",
                                               "effort_limit",
                                               "delay_samples"};
  for (const auto& entry : doc) {
    const std::string key = entry.first.as<std::string>();
    if (!kKnown.count(key))
      throw Error("gains file " + path + ": unknown key '" + one_line(key) +
                  "'; the gains are kp, ki, kd");
  }
  const int n = model.dof();
  PidGains out{read_gain_list(doc, "kp", path, n), read_gain_list(doc, "ki", path, n),
               read_gain_list(doc, "kd", path, n), ""};
  if (doc["controller"]) {
    try {
      out.controller = doc["controller"].as<std::string>();
    } catch (const YAML::Exception&) {
      throw Error("gains file " + path + ": 'controller' must be a name, e.g. pid");
    }
  }
  return out;
}

std::string gains_file_for_run(const std::string& run_path) {
  const std::string suffix = ".csv";
  const bool csv = run_path.size() > suffix.size() &&
                   run_path.compare(run_path.size() - suffix.size(), suffix.size(), suffix) == 0;
  return (csv ? run_path.substr(0, run_path.size() - suffix.size()) : run_path) + ".gains.json";
}

nlohmann::json pid_gains_to_json(const Model& model, const PidOptions& pid, int delay_samples) {
  auto list = [](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  std::vector<std::string> joints;
  for (const Joint& j : model.joints) joints.push_back(j.name);
  nlohmann::json out;
  out["controller"] = pid.feed_forward == FeedForward::kNone              ? "pid"
                      : pid.feed_forward == FeedForward::kInverseDynamics ? "computed-torque"
                                                                          : "pid-feedforward";
  out["joints"] = joints;
  out["kp"] = list(pid.kp);
  out["ki"] = list(pid.ki);
  out["kd"] = list(pid.kd);
  out["sample_time"] = pid.sample_time;
  out["derivative_filter_time"] = pid.derivative_filter_time;
  out["effort_limit"] = list(pid.effort_limit);
  out["delay_samples"] = delay_samples;
  return out;
}

void write_pid_gains(const std::string& path, const Model& model, const PidOptions& pid,
                     int delay_samples) {
  write_json(path, pid_gains_to_json(model, pid, delay_samples));
}

}  // namespace dynid
