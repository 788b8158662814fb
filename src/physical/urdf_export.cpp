#include "dynid/physical/urdf_export.hpp"

#include <tinyxml2.h>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/io/urdf_writer.hpp"
#include "dynid/model/urdf_loader.hpp"
#include "dynid/version.hpp"

namespace dynid {

namespace {

// The shortest decimal that reads back as the same double (0.3, not 0.29999999999999999).
std::string number(double x) {
  char buf[64];
  if (x == 0.0) x = 0.0;  // no "-0"
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof(buf), "%.*g", digits, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// "Fvp12" -> ("Fvp", 12); a name without a trailing 1-based index gives index 0.
std::pair<std::string, int> split_name(const std::string& name) {
  size_t k = name.size();
  while (k > 0 && std::isdigit(static_cast<unsigned char>(name[k - 1]))) --k;
  if (k == name.size() || k == 0 || name.size() - k > 6) return {name, 0};
  return {name.substr(0, k), std::stoi(name.substr(k))};
}

// Per-joint terms of one joint as found in the file (NaN = not given).
struct JointTerms {
  double Ia = NAN, Fv = NAN, Fc = NAN, Fo = NAN, Fvp = NAN, Fvn = NAN, Fcp = NAN, Fcn = NAN;
};

std::string comment_safe(std::string s) {
  for (size_t k; (k = s.find("--")) != std::string::npos;) s.replace(k, 2, "- -");
  return s;
}

// Replaces (or adds) the <inertial> of `link` with the link's identified one.
void set_inertial(tinyxml2::XMLDocument& doc, tinyxml2::XMLElement* link, const LinkParams& p) {
  const ComInertial in = com_inertial(p);
  tinyxml2::XMLElement* inertial = doc.NewElement("inertial");
  tinyxml2::XMLElement* origin = inertial->InsertNewChildElement("origin");
  origin->SetAttribute(
      "xyz", (number(in.com.x()) + ' ' + number(in.com.y()) + ' ' + number(in.com.z())).c_str());
  origin->SetAttribute("rpy", "0 0 0");
  inertial->InsertNewChildElement("mass")->SetAttribute("value", number(in.mass).c_str());
  tinyxml2::XMLElement* I = inertial->InsertNewChildElement("inertia");
  static const char* kNames[3][3] = {{"ixx", "ixy", "ixz"}, {"", "iyy", "iyz"}, {"", "", "izz"}};
  for (int r = 0; r < 3; ++r)
    for (int c = r; c < 3; ++c) I->SetAttribute(kNames[r][c], number(in.inertia(r, c)).c_str());
  tinyxml2::XMLElement* old = link->FirstChildElement("inertial");
  if (old) {
    link->InsertAfterChild(old, inertial);
    link->DeleteChild(old);
  } else {
    link->InsertFirstChild(inertial);
  }
}

std::string print(const tinyxml2::XMLDocument& doc) {
  tinyxml2::XMLPrinter printer;
  doc.Print(&printer);
  return printer.CStr();
}

}  // namespace

ConsistentParameterFile read_consistent_parameters(const std::string& path) {
  require_regular_file(path, "result file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open result file '" + path + "'; check the path");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const std::exception& e) {
    throw Error("'" + path + "' is not valid JSON (" + std::string(e.what()) +
                "); give the result.json of dynid identify --physical");
  }
  if (!j.is_object() || !j.contains("standard_parameters")) {
    throw Error("'" + path +
                "' has no standard_parameters; identify with --physical (dynid identify "
                "--physical ...) and export that result");
  }
  const auto consistent = j.find("physically_consistent");
  if (consistent == j.end() || !consistent->is_boolean() || !consistent->get<bool>()) {
    throw Error("'" + path +
                "' is not physically consistent (physically_consistent is not true): a "
                "simulator would reject its inertias; identify again with --physical on a run "
                "that excites every parameter");
  }
  const nlohmann::json& list = j["standard_parameters"];
  if (!list.is_array() || list.empty()) {
    throw Error("'" + path + "': standard_parameters must be a non-empty list of {name, value}");
  }
  ConsistentParameterFile out;
  out.values.resize(static_cast<Eigen::Index>(list.size()));
  for (size_t i = 0; i < list.size(); ++i) {
    const auto& p = list[i];
    if (!p.is_object() || !p.contains("name") || !p["name"].is_string() || !p.contains("value") ||
        !p["value"].is_number() || !std::isfinite(p["value"].get<double>())) {
      throw Error("'" + path + "': standard_parameters[" + std::to_string(i) +
                  "] needs a string name and a finite numeric value");
    }
    out.names.push_back(p["name"].get<std::string>());
    out.values[static_cast<Eigen::Index>(i)] = p["value"].get<double>();
  }
  const auto model = j.find("model");
  if (model != j.end() && model->is_object()) {
    if (model->contains("name") && (*model)["name"].is_string())
      out.robot = (*model)["name"].get<std::string>();
    if (model->contains("joints") && (*model)["joints"].is_array()) {
      for (const auto& name : (*model)["joints"])
        if (name.is_string()) out.joints.push_back(name.get<std::string>());
    }
  }
  out.locked_joints = locked_joints_from_json(j, path);
  return out;
}

Model model_with_standard_parameters(const Model& nominal, const std::vector<std::string>& names,
                                     const Eigen::VectorXd& values) {
  if (static_cast<Eigen::Index>(names.size()) != values.size()) {
    throw Error("standard parameters: " + std::to_string(names.size()) + " names but " +
                std::to_string(values.size()) + " values");
  }
  const int n = nominal.dof();
  const std::vector<std::string>& labels = link_parameter_labels();
  std::vector<std::array<bool, kLinkParams>> seen(static_cast<size_t>(n));
  for (auto& s : seen) s.fill(false);
  std::vector<JointTerms> terms(static_cast<size_t>(n));
  Model out = nominal;
  for (size_t i = 0; i < names.size(); ++i) {
    const auto [label, joint] = split_name(names[i]);
    const double v = values[static_cast<Eigen::Index>(i)];
    if (label == "Iam" || label == "Fvm" || label == "Fcm") continue;  // coupled motors
    if (joint < 1 || joint > n) {
      throw Error("standard parameter '" + names[i] + "' names no joint of robot '" + nominal.name +
                  "' (" + std::to_string(n) +
                  " joints); export with the robot it was identified on");
    }
    const size_t j = static_cast<size_t>(joint - 1);
    const auto it = std::find(labels.begin(), labels.end(), label);
    if (it != labels.end()) {
      const int k = static_cast<int>(it - labels.begin());
      out.links[j][k] = v;
      seen[j][static_cast<size_t>(k)] = true;
      continue;
    }
    JointTerms& t = terms[j];
    double* slot = label == "Ia"    ? &t.Ia
                   : label == "Fv"  ? &t.Fv
                   : label == "Fc"  ? &t.Fc
                   : label == "Fo"  ? &t.Fo
                   : label == "Fvp" ? &t.Fvp
                   : label == "Fvn" ? &t.Fvn
                   : label == "Fcp" ? &t.Fcp
                   : label == "Fcn" ? &t.Fcn
                                    : nullptr;
    if (!slot) {
      throw Error("'" + names[i] +
                  "' is not a standard parameter name (XXj..Mj, Iaj, Fvj, Fcj, Foj, Fvpj, Fvnj, "
                  "Fcpj, Fcnj, Iamk, Fvmk, Fcmk; docs/design.md section 3)");
    }
    *slot = v;
  }
  for (int j = 0; j < n; ++j) {
    for (int k = 0; k < kLinkParams; ++k) {
      if (!seen[static_cast<size_t>(j)][static_cast<size_t>(k)]) {
        throw Error("standard parameter " + labels[static_cast<size_t>(k)] + std::to_string(j + 1) +
                    " is missing; every link's 10 parameters are needed to export a model");
      }
    }
    const JointTerms& t = terms[static_cast<size_t>(j)];
    JointFriction& f = out.joints[static_cast<size_t>(j)].friction;
    if (!std::isnan(t.Ia)) f.Ia = t.Ia;
    if (!std::isnan(t.Fv)) f.Fv = t.Fv;
    if (!std::isnan(t.Fc)) f.Fc = t.Fc;
    if (!std::isnan(t.Fo)) f.Fo = t.Fo;
    if (!std::isnan(t.Fvp) && !std::isnan(t.Fvn)) f.Fv = 0.5 * (t.Fvp + t.Fvn);
    if (!std::isnan(t.Fcp) && !std::isnan(t.Fcn)) f.Fc = 0.5 * (t.Fcp + t.Fcn);
  }
  out.finalize();
  return out;
}

UrdfExport export_urdf(const Model& nominal, const std::vector<std::string>& names,
                       const Eigen::VectorXd& values, const std::string& origin) {
  UrdfExport out;
  out.model = model_with_standard_parameters(nominal, names, values);
  const int n = nominal.dof();
  // Which joints' damping/friction the file identified, and what URDF cannot hold.
  std::vector<bool> has_fv(static_cast<size_t>(n), false), has_fc(static_cast<size_t>(n), false);
  for (size_t i = 0; i < names.size(); ++i) {
    const auto [label, joint] = split_name(names[i]);
    const std::string v = names[i] + " = " + number(values[static_cast<Eigen::Index>(i)]);
    if (label == "Fv" || label == "Fvp") has_fv[static_cast<size_t>(joint - 1)] = true;
    if (label == "Fc" || label == "Fcp") has_fc[static_cast<size_t>(joint - 1)] = true;
    if (label == "Ia") out.not_in_urdf.push_back(v + " (armature: URDF has no element for it)");
    if (label == "Fo") out.not_in_urdf.push_back(v + " (torque offset: not a URDF term)");
    if (label == "Fvp" || label == "Fvn" || label == "Fcp" || label == "Fcn") {
      out.not_in_urdf.push_back(
          v + " (asymmetric friction: URDF holds one level, the mean of both directions)");
    }
    if (label == "Iam" || label == "Fvm" || label == "Fcm") {
      out.not_in_urdf.push_back(v + " (coupled motor term: URDF has no transmission dynamics)");
    }
  }
  if (nominal.gravity != Eigen::Vector3d(0.0, 0.0, -9.81)) {
    out.not_in_urdf.push_back("gravity = (" + number(nominal.gravity.x()) + ", " +
                              number(nominal.gravity.y()) + ", " + number(nominal.gravity.z()) +
                              ") m/s^2 (URDF has no gravity; set it in the simulator)");
  }
  // The URDF the frames came from: a .urdf model's own file, or the one a YAML model names.
  const std::string urdf = !nominal.urdf.empty()                ? nominal.urdf
                           : ends_with(nominal.source, ".urdf") ? nominal.source
                                                                : std::string();
  const bool edit = !urdf.empty();
  const std::string xml = edit ? read_robot_file(urdf) : to_urdf(out.model);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    throw Error("cannot parse URDF '" + urdf + "' (" + doc.ErrorStr() + ")");
  }
  tinyxml2::XMLElement* robot = doc.FirstChildElement("robot");
  if (!robot) throw Error("URDF '" + urdf + "' has no <robot> element");
  if (edit) {
    std::map<std::string, tinyxml2::XMLElement*> links, joints;
    std::multimap<std::string, std::string> fixed_children;  // parent link -> child link
    for (auto* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
      if (const char* name = e->Attribute("name")) links[name] = e;
    }
    auto link_of = [](tinyxml2::XMLElement* joint, const char* which) -> std::string {
      const tinyxml2::XMLElement* e = joint->FirstChildElement(which);
      const char* name = e ? e->Attribute("link") : nullptr;
      return name ? name : "";
    };
    for (auto* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
      if (const char* name = e->Attribute("name")) joints[name] = e;
      const char* type = e->Attribute("type");
      const char* name = e->Attribute("name");
      // A joint held during identification (Model::locked_joints) was merged like a fixed one.
      const bool locked =
          name && std::any_of(nominal.locked_joints.begin(), nominal.locked_joints.end(),
                              [name](const JointLock& l) { return l.name == name; });
      if ((type && std::string(type) == "fixed") || locked)
        fixed_children.emplace(link_of(e, "parent"), link_of(e, "child"));
    }
    for (int j = 0; j < n; ++j) {
      const Joint& joint = nominal.joints[static_cast<size_t>(j)];
      const auto it = joints.find(joint.name);
      if (it == joints.end()) {
        throw Error("joint '" + joint.name + "' of the model is not in URDF '" + urdf + "'");
      }
      const std::string child = link_of(it->second, "child");
      if (!links.count(child)) {
        throw Error("link '" + child + "' of joint '" + joint.name + "' is not in URDF '" + urdf +
                    "'");
      }
      set_inertial(doc, links[child], out.model.links[static_cast<size_t>(j)]);
      // Links rigidly attached to this one were merged into it by the loader, so the identified
      // inertia is theirs too: keeping their <inertial> would count them twice.
      std::vector<std::string> stack{child};
      while (!stack.empty()) {
        const std::string parent = stack.back();
        stack.pop_back();
        const auto [lo, hi] = fixed_children.equal_range(parent);
        for (auto c = lo; c != hi; ++c) {
          stack.push_back(c->second);
          auto l = links.find(c->second);
          if (l == links.end()) continue;
          if (tinyxml2::XMLElement* inertial = l->second->FirstChildElement("inertial")) {
            l->second->DeleteChild(inertial);
            out.merged_links.push_back(c->second);
          }
        }
      }
      if (has_fv[static_cast<size_t>(j)] || has_fc[static_cast<size_t>(j)]) {
        tinyxml2::XMLElement* dynamics = it->second->FirstChildElement("dynamics");
        if (!dynamics) dynamics = it->second->InsertNewChildElement("dynamics");
        const JointFriction& f = out.model.joints[static_cast<size_t>(j)].friction;
        if (has_fv[static_cast<size_t>(j)]) dynamics->SetAttribute("damping", number(f.Fv).c_str());
        if (has_fc[static_cast<size_t>(j)])
          dynamics->SetAttribute("friction", number(f.Fc).c_str());
      }
    }
  }
  std::ostringstream note;
  note << " Identified by dynid " << kVersion << " from '" << origin
       << "': physically consistent inertials";
  if (edit) note << " and joint <dynamics> replaced, every other element kept";
  if (!nominal.locked_joints.empty()) {
    note << ". Joints held during identification (their links' inertia is in the moving parent's):";
    for (const JointLock& l : nominal.locked_joints)
      note << ' ' << l.name << '=' << number(l.value);
  }
  if (!out.merged_links.empty()) {
    note << ". Links merged into their moving parent (inertial removed):";
    for (const auto& l : out.merged_links) note << ' ' << l;
  }
  if (!out.not_in_urdf.empty()) {
    note << ". Identified terms URDF cannot hold:";
    for (const auto& t : out.not_in_urdf) note << "\n  " << t;
    note << '\n';
  }
  note << ' ';
  robot->InsertFirstChild(doc.NewComment(comment_safe(note.str()).c_str()));
  out.text = print(doc);
  return out;
}

}  // namespace dynid
