#pragma once

// The Model whose dynamics are those of identified base parameters, the rest nominal: what
// simulation, computed-torque control and model completion build on.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/identification/identify.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// A Model whose dynamics are those of identified base parameters: the dependent standard
/// parameters theta_2 keep the nominal model's values and theta_1 = theta_b − K_d·theta_2
/// (Gautier–Khalil), so tau = Y·theta equals the identified base model exactly; the unidentifiable
/// parameters keep their nominal values. Friction/armature columns go to Joint::friction
/// (asymmetric pairs as mean and asymmetry, JointFriction::Fva/Fca; coupled-motor columns cannot be
/// represented and are dropped; terms that are not in options.layout keep their nominal values).
/// The individual links need not be physically consistent (only theta_b is identified), so the
/// model is not finalize()d. Throws dynid::Error for a name that is not a base parameter of the
/// model with options.layout.
Model identified_model(const Model& nominal, const std::vector<std::string>& names,
                       const Eigen::VectorXd& values, const IdentifyOptions& options);

}  // namespace dynid
