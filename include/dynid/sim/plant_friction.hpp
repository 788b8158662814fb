#pragma once

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid {

/// Friction of a simulated plant. It deliberately differs from the identified model's
/// Fv·dq + Fc·sign(dq) + Fo (seed 1 eq. 3, seed 2 eq. 2): Coulomb is smoothed by tanh and an
/// optional Stribeck/stiction bump can be added, so that simulated test data do not come from the
/// estimator's own equations.
struct PlantFrictionOptions {
  bool viscous = true;               ///< apply Fv·dq from Joint::friction
  bool coulomb = true;               ///< apply the (smoothed) Coulomb term from Joint::friction.Fc
  bool offset = true;                ///< apply the constant offset Fo from Joint::friction
  double smoothing_velocity = 1e-2;  ///< v_s of tanh(dq/v_s) [rad/s or m/s]; must be > 0
  Eigen::VectorXd stiction;          ///< breakaway level Fs per joint [N·m or N]; empty = none
  double stribeck_velocity = 5e-2;   ///< v_st of the Stribeck bump exp(−(dq/v_st)²); > 0
};

/// Joint-side friction torque of the simulated plant, per joint j:
/// F_j = Fv·dq + (Fc + (Fs − Fc)·exp(−(dq/v_st)²))·tanh(dq/v_s) + Fo (Fs = Fc without stiction),
/// which tends to Fv·dq + Fc·sign(dq) + Fo (seed 1 eq. 3) as v_s → 0 and |dq| ≫ v_st.
/// dq and out have size model.dof(). No allocation. Options must have been checked with
/// check_plant_friction().
void plant_friction_torque(const Model& model, const PlantFrictionOptions& options,
                           const Eigen::Ref<const Eigen::VectorXd>& dq,
                           Eigen::Ref<Eigen::VectorXd> out);

/// Checks the options against the model. Throws dynid::Error naming the field at fault
/// (non-positive or non-finite velocities, stiction vector of the wrong size or negative).
void check_plant_friction(const Model& model, const PlantFrictionOptions& options);

/// Largest slope |∂F_j/∂dq| over all velocities, an upper bound used to pick a stable explicit
/// step: Fv + Fc/v_s + |Fs − Fc|·(1/v_s + √2·e^{−1/2}/v_st) [N·m·s/rad].
double plant_friction_max_slope(const JointFriction& friction, const PlantFrictionOptions& options,
                                int joint);

}  // namespace dynid
