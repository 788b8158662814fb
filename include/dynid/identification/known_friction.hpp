#pragma once

// Friction identified before (seed 2 §3.4) and subtracted from the measured torque of the
// differential equations, then added back to the result so that it predicts full torques.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/estimation/equation_block.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

struct ProcessedRecord;

/// Joint friction identified before (seed 2 §3.4, Table 2; e.g. by fit_friction_experiment() or
/// fit_decoupled_joint()), in the asymmetric form of seed 2 eq. 2:
///   τ_f,j = Fvp_j·q̇·[q̇>0] + Fvn_j·q̇·[q̇<0] + Fcp_j·[q̇>0] − Fcn_j·[q̇<0].
struct KnownFriction {
  Eigen::VectorXd fvp;  ///< per joint, viscous for q̇ > 0 [N·m·s/rad]; size n or empty (none)
  Eigen::VectorXd fvn;  ///< per joint, viscous for q̇ < 0 [N·m·s/rad]
  Eigen::VectorXd fcp;  ///< per joint, Coulomb for q̇ > 0 [N·m]
  Eigen::VectorXd fcn;  ///< per joint, Coulomb for q̇ < 0 [N·m] (the torque is −Fcn)
  std::vector<bool> given;  ///< per joint: friction known; joints not given contribute 0
  bool empty() const { return given.empty(); }
};

/// Adds the friction of a previous result (parameters named Fvp<J> Fvn<J> Fcp<J> Fcn<J>, 1-based
/// J, as fit_friction_experiment() and fit_decoupled_joint() name them; other names ignored) to
/// `friction`, sized for `model` on first use. Throws dynid::Error naming `source` when it has no
/// friction parameter, a joint outside the model, an incomplete set of four for a joint, a joint
/// already given by another source, or a non-finite value.
void add_known_friction(KnownFriction& friction, const Model& model,
                        const std::vector<std::string>& names, const Eigen::VectorXd& values,
                        const std::string& source);

/// Subtracts the known friction torque from the measured side of a differential block built from
/// `processed` (rows grouped by joint, `sample` indexing processed.record): y_i −= τ_f,j(q̇_k).
/// The indicators are the Coulomb columns identify() uses (the filtered expected-sign columns
/// when the processed run carries them), so the subtracted torque is filtered like τ. Throws
/// dynid::Error when the sizes do not match the model.
void subtract_known_friction(const Model& model, const KnownFriction& friction,
                             const ProcessedRecord& processed, EquationBlock& block);

/// The known friction of the joints given, as the parameters Fvp<J> Fvn<J> Fcp<J> Fcn<J> (1-based
/// J) that add_known_friction() reads back: what a result identified with it stores, so that it
/// can be validated and simulated with its friction.
void known_friction_parameters(const KnownFriction& friction, std::vector<std::string>& names,
                               Eigen::VectorXd& values);

/// Turns a rigid-body result fitted after subtract_known_friction() into one that predicts the
/// full torque: appends Fvp<J> Fvn<J> Fcp<J> Fcn<J> of every joint (0 for the joints not given)
/// to `names`/`values` and switches `layout` to asymmetric viscous and Coulomb columns, so that
/// validate_torques() and identified_model() add the friction that the fit subtracted (seed 2
/// §3.4). Throws dynid::Error when `layout` already has friction columns or the sizes differ.
void append_known_friction(const KnownFriction& friction, std::vector<std::string>& names,
                           Eigen::VectorXd& values, ParameterLayout& layout);

}  // namespace dynid
