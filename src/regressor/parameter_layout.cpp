#include "dynid/regressor/parameter_layout.hpp"

#include <cctype>
#include <string>

namespace dynid {

ParameterLayout ParameterLayout::full() {
  ParameterLayout l;
  l.armature = l.viscous = l.coulomb = l.offset = true;
  return l;
}

int ParameterLayout::joint_columns() const {
  const int friction_cols = (viscous ? 1 : 0) + (coulomb ? 1 : 0);
  return (armature ? 1 : 0) + (asymmetric ? 2 * friction_cols : friction_cols) + (offset ? 1 : 0);
}

std::vector<std::string> ParameterLayout::names(int dof) const {
  std::vector<std::string> out;
  out.reserve(columns(dof));
  for (int j = 0; j < dof; ++j) {
    for (const auto& label : link_parameter_labels()) out.push_back(label + std::to_string(j + 1));
  }
  for (int j = 0; j < dof; ++j) {
    const std::string k = std::to_string(j + 1);
    if (armature) out.push_back("Ia" + k);
    if (asymmetric) {
      if (viscous) {
        out.push_back("Fvp" + k);
        out.push_back("Fvn" + k);
      }
      if (coulomb) {
        out.push_back("Fcp" + k);
        out.push_back("Fcn" + k);
      }
    } else {
      if (viscous) out.push_back("Fv" + k);
      if (coulomb) out.push_back("Fc" + k);
    }
    if (offset) out.push_back("Fo" + k);
  }
  return out;
}

std::string parameter_unit(const Model& model, const std::string& name) {
  std::size_t digits = name.find_first_of("0123456789");
  if (digits == std::string::npos || digits == 0) return "";
  const std::string kind = name.substr(0, digits);
  std::size_t end = digits;
  while (end < name.size() && std::isdigit(static_cast<unsigned char>(name[end]))) ++end;
  if (end < name.size() && name.substr(end) != "R") return "";
  if (end - digits > 4) return "";  // more joints than kMaxJoints allows
  const int joint = std::stoi(name.substr(digits, end - digits));
  if (joint < 1 || joint > model.dof()) return "";
  if (kind == "M") return "kg";
  if (kind == "MX" || kind == "MY" || kind == "MZ") return "kg·m";
  for (const char* inertia : {"XX", "XY", "XZ", "YY", "YZ", "ZZ"}) {
    if (kind == inertia) return "kg·m²";
  }
  const bool prismatic = model.joints[joint - 1].type == JointType::kPrismatic;
  // Iam, Fvm, Fcm: a coupled motor's terms (coupling_column_names), in its joint's units.
  if (kind == "Ia" || kind == "Iam") return prismatic ? "kg" : "kg·m²";
  if (kind == "Fv" || kind == "Fvp" || kind == "Fvn" || kind == "Fvm") {
    return prismatic ? "N·s/m" : "N·m·s/rad";
  }
  if (kind == "Fc" || kind == "Fcp" || kind == "Fcn" || kind == "Fcm" || kind == "Fo") {
    return prismatic ? "N" : "N·m";
  }
  return "";
}

Eigen::VectorXd ParameterLayout::parameters(const Model& model) const {
  const int n = model.dof();
  Eigen::VectorXd theta(columns(n));
  theta.head(kLinkParams * n) = model.standard_parameters();
  int c = kLinkParams * n;
  for (int j = 0; j < n; ++j) {
    const JointFriction& f = model.joints[j].friction;
    if (armature) theta[c++] = f.Ia;
    const int repeat = asymmetric ? 2 : 1;
    // Asymmetric pairs are (positive, negative) = mean ± asymmetry (seed 2 eq. 2).
    if (viscous)
      for (int r = 0; r < repeat; ++r) theta[c++] = f.Fv + (asymmetric ? (r ? -f.Fva : f.Fva) : 0);
    if (coulomb)
      for (int r = 0; r < repeat; ++r) theta[c++] = f.Fc + (asymmetric ? (r ? -f.Fca : f.Fca) : 0);
    if (offset) theta[c++] = f.Fo;
  }
  return theta;
}

}  // namespace dynid
