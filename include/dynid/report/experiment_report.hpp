#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/experiments/decoupled_model.hpp"
#include "dynid/experiments/friction_experiment.hpp"
#include "dynid/experiments/gravity_experiment.hpp"
#include "dynid/model/model.hpp"
#include "dynid/physical/physical_parameters.hpp"

namespace dynid {

/// Result JSON of `dynid identify --model gravity` (seed 2 Table 1): `parameters` k<J>, qoff<J>
/// (name, value, std, relative_std_percent, ci_low, ci_high) as identify writes them, plus
/// `slopes` (name, velocity, offset, offset_std, rows), `fit` (the cruise samples: run, q, tau,
/// fitted) for plotting, `choices`, `warnings`, `options` and the version.
nlohmann::json gravity_experiment_to_json(const Model& model, const GravityExperimentResult& r,
                                          const nlohmann::json& options_used);

/// Result JSON of `dynid identify --model gravity` when the runs hold the other joints at
/// several poses (fit_gravity_poses()): `parameters` the gravity base parameters of joint J with
/// `base_parameters` (name, expression), `poses` (pose, k, k_std, k_ci_half_width, qoff,
/// qoff_std, qoff_ci_half_width) for comparison with seed 2 Table 1, and `slopes` as above.
nlohmann::json gravity_poses_to_json(const Model& model, const GravityPosesResult& r,
                                     const nlohmann::json& options_used);

/// Result JSON of `dynid identify --model friction` (seed 2 Table 2): `parameters` Fvp<J> Fvn<J>
/// Fcp<J> Fcn<J>, `curve` (velocity, torque) and `fit` (run, t, dq, tau, fitted) for plotting.
nlohmann::json friction_experiment_to_json(const Model& model, const FrictionExperimentResult& r,
                                           const nlohmann::json& options_used);

/// Result JSON of `dynid identify --model decoupled` (seed 2 eqs. 21–22): `parameters` M<J>,
/// k<J>, qoff<J>, Fvp<J> Fvn<J> Fcp<J> Fcn<J>, `held_span` and `coupling_ratio` per joint.
nlohmann::json decoupled_model_to_json(const Model& model, const DecoupledJointResult& r,
                                       const nlohmann::json& options_used);

/// Adds the physically consistent fit to an identify result JSON: `standard_parameters` (name,
/// value), `physically_consistent` and `physical` (mahalanobis = distance_sigma, chi2_limit,
/// within_limit, nominal_distance, converged, relative_error of the consistent set and
/// relative_error_unconstrained, warnings); the warnings are also appended to `warnings`.
void physical_parameters_to_json(const PhysicalFit& fit, double relative_error,
                                 double relative_error_unconstrained, nlohmann::json& result,
                                 const std::vector<std::string>& warnings = {});

/// Two lines for the terminal: how far the consistent set is and what it costs in torque error.
std::string physical_parameters_text(const PhysicalFit& fit, double relative_error,
                                     double relative_error_unconstrained);

/// The `parameters` of one of these JSON results as a table for the terminal, with its warnings.
std::string experiment_table(const nlohmann::json& result);

}  // namespace dynid
