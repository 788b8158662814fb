#include "dynid/physical/identified_model.hpp"

#include <algorithm>

#include "dynid/common/error.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/transmission.hpp"

namespace dynid {

Model identified_model(const Model& nominal, const std::vector<std::string>& names,
                       const Eigen::VectorXd& values, const IdentifyOptions& options) {
  BaseParameterOptions bo = options.base;
  bo.layout = options.layout;
  bo.coupling = options.coupling && !coupled_motors(nominal).empty();
  const BaseParameters base = compute_base_parameters(nominal, bo);
  const int n = nominal.dof();
  const int p = options.layout.columns(n);
  Eigen::VectorXd theta =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(base.layout_names.size()));
  theta.head(p) = options.layout.parameters(nominal);
  Eigen::VectorXd theta_b = base.reduce(theta);
  for (size_t i = 0; i < names.size(); ++i) {
    const auto it = std::find(base.names.begin(), base.names.end(), names[i]);
    if (it == base.names.end()) {
      throw Error("parameter '" + names[i] + "' is not a base parameter of model '" + nominal.name +
                  "' with this friction set; validate with the options used to identify");
    }
    theta_b[it - base.names.begin()] = values[static_cast<Eigen::Index>(i)];
  }
  // theta_1 = theta_b − K_d·theta_2 with theta_2 at its nominal values.
  for (int i = 0; i < base.rank; ++i) {
    double regrouped = 0.0;
    for (size_t j = 0; j < base.dependent.size(); ++j)
      regrouped += base.K_d(i, j) * theta[base.dependent[j]];
    theta[base.base[i]] = theta_b[i] - regrouped;
  }
  Model out = nominal;
  for (int j = 0; j < n; ++j) out.links[j] = theta.segment<kLinkParams>(kLinkParams * j);
  const int jc = options.layout.joint_columns();
  for (int j = 0; j < n; ++j) {
    const double* c = theta.data() + kLinkParams * n + jc * j;
    JointFriction& f = out.joints[j].friction;
    int k = 0;
    if (options.layout.armature) f.Ia = c[k++];
    const int repeat = options.layout.asymmetric ? 2 : 1;
    // Asymmetric pairs (positive, negative) become mean and asymmetry, which joint_torque()
    // turns back into the sign-dependent law of seed 2 eq. 2.
    if (options.layout.viscous) {
      f.Fv = repeat == 2 ? 0.5 * (c[k] + c[k + 1]) : c[k];
      f.Fva = repeat == 2 ? 0.5 * (c[k] - c[k + 1]) : 0.0;
      k += repeat;
    }
    if (options.layout.coulomb) {
      f.Fc = repeat == 2 ? 0.5 * (c[k] + c[k + 1]) : c[k];
      f.Fca = repeat == 2 ? 0.5 * (c[k] - c[k + 1]) : 0.0;
      k += repeat;
    }
    if (options.layout.offset) f.Fo = c[k++];
  }
  return out;
}

}  // namespace dynid