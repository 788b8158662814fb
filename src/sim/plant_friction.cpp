#include "dynid/sim/plant_friction.hpp"

#include <cmath>
#include <string>

#include "dynid/common/error.hpp"

namespace dynid {

void plant_friction_torque(const Model& model, const PlantFrictionOptions& options,
                           const Eigen::Ref<const Eigen::VectorXd>& dq,
                           Eigen::Ref<Eigen::VectorXd> out) {
  const int n = model.dof();
  const bool stiction = options.stiction.size() == n;
  for (int j = 0; j < n; ++j) {
    const JointFriction& f = model.joints[j].friction;
    double tau = 0.0;
    if (options.viscous) tau += f.Fv * dq[j] + f.Fva * std::abs(dq[j]);
    if (options.coulomb) {
      // F = (Fc + (Fs − Fc)·exp(−(dq/v_st)²))·tanh(dq/v_s) (Stribeck curve with tanh smoothing).
      double level = f.Fc;
      if (stiction) {
        const double r = dq[j] / options.stribeck_velocity;
        level += (options.stiction[j] - f.Fc) * std::exp(-r * r);
      }
      const double smooth_sign = std::tanh(dq[j] / options.smoothing_velocity);
      tau += level * smooth_sign + f.Fca * std::abs(smooth_sign);
    }
    if (options.offset) tau += f.Fo;
    out[j] = tau;
  }
}

void check_plant_friction(const Model& model, const PlantFrictionOptions& options) {
  if (!(options.smoothing_velocity > 0.0) || !std::isfinite(options.smoothing_velocity))
    throw Error("plant friction smoothing_velocity must be a finite value > 0 [rad/s], e.g. 0.01");
  if (!(options.stribeck_velocity > 0.0) || !std::isfinite(options.stribeck_velocity))
    throw Error("plant friction stribeck_velocity must be a finite value > 0 [rad/s], e.g. 0.05");
  if (options.stiction.size() != 0) {
    if (options.stiction.size() != model.dof())
      throw Error("plant friction stiction has " + std::to_string(options.stiction.size()) +
                  " entries but the model has " + std::to_string(model.dof()) +
                  " joints: give one breakaway level per joint or none");
    for (int j = 0; j < model.dof(); ++j)
      if (!(options.stiction[j] >= 0.0) || !std::isfinite(options.stiction[j]))
        throw Error("plant friction stiction of joint '" + model.joints[j].name +
                    "' must be finite and >= 0");
  }
}

double plant_friction_max_slope(const JointFriction& friction, const PlantFrictionOptions& options,
                                int joint) {
  double slope = options.viscous ? std::abs(friction.Fv) + std::abs(friction.Fva) : 0.0;
  if (options.coulomb) {
    slope += (std::abs(friction.Fc) + std::abs(friction.Fca)) / options.smoothing_velocity;
    if (options.stiction.size() > joint) {
      const double bump = std::abs(options.stiction[joint] - friction.Fc);
      slope += bump * (1.0 / options.smoothing_velocity +
                       std::sqrt(2.0) * std::exp(-0.5) / options.stribeck_velocity);
    }
  }
  return slope;
}

}  // namespace dynid
