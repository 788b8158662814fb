#include "dynid/io/model_summary.hpp"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "dynid/common/error.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/version.hpp"

namespace dynid {
namespace {

const char* type_name(JointType type) {
  return type == JointType::kPrismatic ? "prismatic" : "revolute";
}

std::string fmt(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.6g", v);
  return buffer;
}

std::string parent_name(const Model& model, int parent) {
  return parent < 0 ? std::string("base") : model.joints[static_cast<std::size_t>(parent)].name;
}

void appendf(std::string& out, const char* format, ...) __attribute__((format(printf, 2, 3)));
void appendf(std::string& out, const char* format, ...) {
  char buffer[512];
  va_list args;
  va_start(args, format);
  std::vsnprintf(buffer, sizeof(buffer), format, args);
  va_end(args);
  out += buffer;
}

}  // namespace

nlohmann::json locked_joints_to_json(const Model& model) {
  nlohmann::json out = nlohmann::json::array();
  for (const JointLock& l : model.locked_joints)
    out.push_back({{"name", l.name}, {"value", l.value}});
  return out;
}

std::vector<JointLock> locked_joints_from_json(const nlohmann::json& result,
                                               const std::string& path) {
  std::vector<JointLock> out;
  if (!result.is_object() || !result.contains("locked_joints")) return out;
  const nlohmann::json& list = result["locked_joints"];
  bool ok = list.is_array();
  for (size_t i = 0; ok && i < list.size(); ++i) {
    const nlohmann::json& e = list[i];
    ok = e.is_object() && e.contains("name") && e["name"].is_string() && e.contains("value") &&
         e["value"].is_number() && std::isfinite(e["value"].get<double>());
    if (ok) out.push_back({e["name"].get<std::string>(), e["value"].get<double>()});
  }
  if (!ok) {
    throw Error("'" + path +
                "': locked_joints must be a list of {name, value} (as dynid writes it); give the "
                "result file unedited");
  }
  return out;
}

nlohmann::json model_to_json(const Model& model) {
  using nlohmann::json;
  json j;
  j["name"] = model.name;
  j["source"] = model.source;
  j["dof"] = model.dof();
  j["gravity"] = {model.gravity.x(), model.gravity.y(), model.gravity.z()};
  json joints = json::array();
  json friction = json::array();
  for (const auto& joint : model.joints) {
    joints.push_back(
        {{"name", joint.name},
         {"link", joint.link_name},
         {"type", type_name(joint.type)},
         {"parent", joint.parent < 0 ? json(nullptr) : json(parent_name(model, joint.parent))},
         {"lower", json_number(joint.limits.lower)},
         {"upper", json_number(joint.limits.upper)},
         {"velocity", json_number(joint.limits.velocity)},
         {"effort", json_number(joint.limits.effort)}});
    friction.push_back({{"joint", joint.name},
                        {"Ia", joint.friction.Ia},
                        {"Fv", joint.friction.Fv},
                        {"Fc", joint.friction.Fc},
                        {"Fo", joint.friction.Fo}});
  }
  j["joints"] = joints;
  const auto names = model.standard_parameter_names();
  const Eigen::VectorXd theta = model.standard_parameters();
  json params = json::array();
  for (std::size_t k = 0; k < names.size(); ++k) {
    params.push_back({{"name", names[k]}, {"value", theta(static_cast<Eigen::Index>(k))}});
  }
  j["standard_parameters"] = params;
  j["friction"] = friction;
  json rows = json::array();
  for (Eigen::Index r = 0; r < model.transmission.N.rows(); ++r) {
    json row = json::array();
    for (Eigen::Index c = 0; c < model.transmission.N.cols(); ++c) {
      row.push_back(model.transmission.N(r, c));
    }
    rows.push_back(row);
  }
  json offset = json::array();
  for (Eigen::Index r = 0; r < model.transmission.q_offset.size(); ++r) {
    offset.push_back(model.transmission.q_offset(r));
  }
  j["transmission"] = {{"N", rows}, {"q_offset", offset}};
  j["locked_joints"] = locked_joints_to_json(model);
  j["version"] = kVersion;
  return j;
}

std::string model_summary_text(const Model& model) {
  std::string s;
  appendf(s, "robot      %s\n", model.name.c_str());
  appendf(s, "source     %s\n", model.source.c_str());
  appendf(s, "dof        %d\n", model.dof());
  appendf(s, "gravity    [%s, %s, %s] m/s^2 (base frame)\n", fmt(model.gravity.x()).c_str(),
          fmt(model.gravity.y()).c_str(), fmt(model.gravity.z()).c_str());
  s += "\njoints\n";
  appendf(s, "  %-3s %-16s %-9s %-16s %11s %11s %11s %11s\n", "j", "name", "type", "parent",
          "lower", "upper", "velocity", "effort");
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const Joint& joint = model.joints[j];
    appendf(s, "  %-3zu %-16s %-9s %-16s %11s %11s %11s %11s\n", j + 1, joint.name.c_str(),
            type_name(joint.type), parent_name(model, joint.parent).c_str(),
            fmt(joint.limits.lower).c_str(), fmt(joint.limits.upper).c_str(),
            fmt(joint.limits.velocity).c_str(), fmt(joint.limits.effort).c_str());
  }
  s += "\nstandard parameters (link frame, about the link origin; kg m^2, kg m, kg)\n";
  const auto names = model.standard_parameter_names();
  const Eigen::VectorXd theta = model.standard_parameters();
  for (std::size_t k = 0; k < names.size(); ++k) {
    const bool end_of_line = k % 5 == 4 || k + 1 == names.size();
    appendf(s, "  %-6s %14s%s", names[k].c_str(), fmt(theta(static_cast<Eigen::Index>(k))).c_str(),
            end_of_line ? "\n" : "");
  }
  s += "\nactuator inertia and friction (joint side: tau += Ia*ddq + Fv*dq + Fc*sign(dq) + Fo)\n";
  appendf(s, "  %-3s %-16s %12s %12s %12s %12s\n", "j", "name", "Ia", "Fv", "Fc", "Fo");
  for (std::size_t j = 0; j < model.joints.size(); ++j) {
    const JointFriction& f = model.joints[j].friction;
    appendf(s, "  %-3zu %-16s %12s %12s %12s %12s\n", j + 1, model.joints[j].name.c_str(),
            fmt(f.Ia).c_str(), fmt(f.Fv).c_str(), fmt(f.Fc).c_str(), fmt(f.Fo).c_str());
  }
  s += "\ntransmission (q_motor = N (q - q_offset))";
  if (model.transmission.is_identity()) {
    s += ": identity\n";
  } else {
    s += "\n";
    for (Eigen::Index r = 0; r < model.transmission.N.rows(); ++r) {
      s += "  N  [";
      for (Eigen::Index c = 0; c < model.transmission.N.cols(); ++c) {
        appendf(s, "%s%10s", c ? " " : "", fmt(model.transmission.N(r, c)).c_str());
      }
      s += "]\n";
    }
    s += "  q_offset [";
    for (Eigen::Index r = 0; r < model.transmission.q_offset.size(); ++r) {
      appendf(s, "%s%s", r ? ", " : "", fmt(model.transmission.q_offset(r)).c_str());
    }
    s += "]\n";
  }
  return s;
}

}  // namespace dynid
