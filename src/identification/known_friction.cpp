#include "dynid/identification/known_friction.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"
#include "dynid/identification/record.hpp"

namespace dynid {

void add_known_friction(KnownFriction& friction, const Model& model,
                        const std::vector<std::string>& names, const Eigen::VectorXd& values,
                        const std::string& source) {
  const int n = model.dof();
  if (friction.empty()) {
    friction.given.assign(static_cast<size_t>(n), false);
    for (Eigen::VectorXd* v : {&friction.fvp, &friction.fvn, &friction.fcp, &friction.fcn})
      *v = Eigen::VectorXd::Zero(n);
  }
  const std::vector<std::pair<std::string, Eigen::VectorXd*>> kinds = {{"Fvp", &friction.fvp},
                                                                       {"Fvn", &friction.fvn},
                                                                       {"Fcp", &friction.fcp},
                                                                       {"Fcn", &friction.fcn}};
  std::vector<int> found(static_cast<size_t>(n), 0);
  for (size_t i = 0; i < names.size(); ++i) {
    for (const auto& [prefix, target] : kinds) {
      const std::string& name = names[i];
      if (name.rfind(prefix, 0) != 0 || name.size() == prefix.size() ||
          name.find_first_not_of("0123456789", prefix.size()) != std::string::npos)
        continue;
      const int j = std::stoi(name.substr(prefix.size())) - 1;
      if (j < 0 || j >= n)
        throw Error("'" + source + "': " + name + " is not a joint of '" + model.name + "' (" +
                    std::to_string(n) + " joints); give a result of this robot");
      if (friction.given[static_cast<size_t>(j)])
        throw Error("'" + source + "': the friction of joint " + std::to_string(j + 1) +
                    " is already given by another file; give each joint once");
      const double v = values[static_cast<Eigen::Index>(i)];
      if (!std::isfinite(v)) throw Error("'" + source + "': " + name + " is not a finite number");
      (*target)[j] = v;
      ++found[static_cast<size_t>(j)];
    }
  }
  bool any = false;
  for (int j = 0; j < n; ++j) {
    if (found[static_cast<size_t>(j)] == 0) continue;
    if (found[static_cast<size_t>(j)] != 4)
      throw Error("'" + source + "': joint " + std::to_string(j + 1) +
                  " needs all four of Fvp, Fvn, Fcp, Fcn (seed 2 eq. 2); give the result of "
                  "identify --model friction or decoupled unedited");
    friction.given[static_cast<size_t>(j)] = true;
    any = true;
  }
  if (!any)
    throw Error("'" + source +
                "' has no friction parameters (Fvp<J> Fvn<J> Fcp<J> Fcn<J>); give "
                "the result of identify --model friction or --model decoupled");
}

void subtract_known_friction(const Model& model, const KnownFriction& friction,
                             const ProcessedRecord& processed, EquationBlock& block) {
  if (friction.empty()) return;
  const int n = model.dof();
  if (static_cast<int>(friction.given.size()) != n || friction.fvp.size() != n ||
      friction.fvn.size() != n || friction.fcp.size() != n || friction.fcn.size() != n)
    throw Error("known friction must have one entry per joint of '" + model.name + "' (" +
                std::to_string(n) + ")");
  // The friction columns of identify() itself (processed_regressor), so the Coulomb step is
  // the filtered expected sign when the run carries it, as in the fit.
  ParameterLayout layout;
  layout.viscous = layout.coulomb = layout.asymmetric = true;
  const Eigen::MatrixXd W = processed_regressor(model, layout, false, processed);
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(layout.columns(n));
  for (int j = 0; j < n; ++j) {
    if (!friction.given[static_cast<size_t>(j)]) continue;
    const Eigen::Index c = kLinkParams * n + layout.joint_columns() * j;
    theta.segment<4>(c) << friction.fvp[j], friction.fvn[j], friction.fcp[j], friction.fcn[j];
  }
  const Eigen::VectorXd tau_f = W * theta;
  for (Eigen::Index i = 0; i < block.y.size(); ++i)
    block.y[i] -= tau_f[static_cast<Eigen::Index>(block.sample[i]) * n + block.group[i]];
}

void known_friction_parameters(const KnownFriction& friction, std::vector<std::string>& names,
                               Eigen::VectorXd& values) {
  names.clear();
  std::vector<double> v;
  for (size_t j = 0; j < friction.given.size(); ++j) {
    if (!friction.given[j]) continue;
    const auto i = static_cast<Eigen::Index>(j);
    const std::string n = std::to_string(j + 1);
    for (const char* prefix : {"Fvp", "Fvn", "Fcp", "Fcn"}) names.push_back(prefix + n);
    v.insert(v.end(), {friction.fvp[i], friction.fvn[i], friction.fcp[i], friction.fcn[i]});
  }
  values = Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

void append_known_friction(const KnownFriction& friction, std::vector<std::string>& names,
                           Eigen::VectorXd& values, ParameterLayout& layout) {
  if (friction.empty()) return;
  if (layout.viscous || layout.coulomb) {
    throw Error(
        "a result identified with known friction has no friction columns of its own; its "
        "options name a friction set too (give the result of identify --friction-known "
        "unedited)");
  }
  if (static_cast<Eigen::Index>(names.size()) != values.size()) {
    throw Error("parameter names and values differ in size");
  }
  const auto n = static_cast<Eigen::Index>(friction.given.size());
  Eigen::VectorXd out(values.size() + 4 * n);
  out.head(values.size()) = values;
  for (Eigen::Index j = 0; j < n; ++j) {
    const bool given = friction.given[static_cast<size_t>(j)];
    const std::string s = std::to_string(j + 1);
    for (const char* prefix : {"Fvp", "Fvn", "Fcp", "Fcn"}) names.push_back(prefix + s);
    out.segment<4>(values.size() + 4 * j) << (given ? friction.fvp[j] : 0.0),
        (given ? friction.fvn[j] : 0.0), (given ? friction.fcp[j] : 0.0),
        (given ? friction.fcn[j] : 0.0);
  }
  values = out;
  layout.viscous = layout.coulomb = layout.asymmetric = true;
}

}  // namespace dynid
