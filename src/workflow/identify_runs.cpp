#include "dynid/workflow/identify_runs.hpp"

#include <utility>

#include "dynid/common/error.hpp"
#include "dynid/experiments/decoupled_model.hpp"
#include "dynid/experiments/friction_experiment.hpp"
#include "dynid/experiments/gravity_experiment.hpp"
#include "dynid/identification/known_friction.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/closed_loop_file.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/report/experiment_report.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/report/stored_result.hpp"

namespace dynid {

IdentifiedRuns identify_runs(const Model& model, const std::vector<JointRecord>& runs,
                             const std::vector<ReferenceRecord>& references,
                             const IdentifyOptions& options,
                             const IdentifyRunsOptions& run_options) {
  const std::string& repeat = run_options.repeat;
  if (!repeat.empty() && repeat != "periods" && repeat != "runs")
    throw UsageError("--repeat must be periods or runs, not '" + repeat + "'");
  const bool closed = options.closed_loop.method != ClosedLoopMethod::kNone;
  // Every check the repeat can fail runs before the whole-run estimate (minutes on a long run).
  RepeatedPieces pieces;
  if (!repeat.empty()) {
    pieces = repeated_pieces(runs, references, options,
                             repeat == "runs" ? RepeatOver::kRuns : RepeatOver::kPeriods);
  }
  IdentifiedRuns out;
  out.result = identify(model, runs, closed ? references : std::vector<ReferenceRecord>{}, options);
  if (!repeat.empty()) out.repeated = identify_repeated(model, pieces, options);
  return out;
}

void identified_runs_to_json(const Model& model, const std::vector<JointRecord>& runs,
                             const IdentifyOptions& options, const IdentifyRunsOptions& run_options,
                             nlohmann::json used, IdentifiedRuns& out,
                             const JointRecord* physical_run) {
  const IdentificationResult& result = out.result;
  // The Coulomb columns identify actually used (the automatic zero-velocity rule turns the
  // filtered expected-sign columns on), so that validate rebuilds the same regressor.
  used["filter_coulomb_columns"] = result.processed.moving_positive.size() != 0;
  if (!options.known_friction.empty()) {
    std::vector<std::string> known_names;
    Eigen::VectorXd known_values;
    known_friction_parameters(options.known_friction, known_names, known_values);
    used["known_friction"] = nlohmann::json::array();
    for (size_t i = 0; i < known_names.size(); ++i)
      used["known_friction"].push_back(
          {{"name", known_names[i]}, {"value", known_values[static_cast<Eigen::Index>(i)]}});
  }
  nlohmann::json& j = out.json;
  j = identification_to_json(model, result, used);
  if (options.closed_loop.method != ClosedLoopMethod::kNone)
    j["closed_loop"] = closed_loop_to_json(result.closed_loop);
  if (out.repeated) j["repeated"] = repeated_to_json(*out.repeated, run_options.repeat);
  // What a report plots: the first run's measured and predicted torques as processed (the
  // streaming mode keeps no run), and the RLS history.
  std::optional<ValidationResult> first_run_fit;
  if (!runs.empty()) {
    IdentifyOptions same = options;
    same.signal.cutoff_hz = result.processed.cutoff_hz;
    same.progress = nullptr;
    std::vector<std::string> names = result.names;
    Eigen::VectorXd values = result.estimate.x;
    append_known_friction(options.known_friction, names, values, same.layout);
    try {
      first_run_fit =
          validate_torques(model, runs.front(), names, values, same, result.not_excited);
      std::vector<std::string> joints;
      for (const auto& joint : model.joints) joints.push_back(joint.name);
      j["plot"] = prediction_plot_json(*first_run_fit, joints);
    } catch (const Error& e) {  // the result stands without its plot
      out.warnings.push_back(std::string("no torque plot in the result: ") + e.what());
    }
    if (result.history_x.rows() > 0) j["plot"]["history"] = rls_history_plot_json(result);
    if (options.model == IdentificationModel::kIntegral)
      j["plot"]["energy"] = energy_plot_json(model, result, options);
  }
  if (run_options.physical) {
    const JointRecord* run = runs.empty() ? physical_run : &runs.front();
    if (run == nullptr) throw Error(run_options.physical_option + " needs a run to measure on");
    out.physical = physical_parameters_of_result(
        model, result, options, *run, run_options.physical_option,
        first_run_fit ? std::optional<double>(first_run_fit->relative_error_all) : std::nullopt);
    const PhysicalCheck& c = *out.physical;
    physical_parameters_to_json(c.fit, c.physical_error, c.free_error, j, c.warnings);
    for (const std::string& w : c.warnings)
      out.warnings.push_back(run_options.physical_option + ": " + w);
  }
}

JointExperiment joint_experiment_of(const std::string& name) {
  if (name == "gravity") return JointExperiment::kGravity;
  if (name == "friction") return JointExperiment::kFriction;
  if (name == "decoupled") return JointExperiment::kDecoupled;
  throw UsageError("the experiment must be gravity, friction or decoupled, not '" + name + "'");
}

nlohmann::json identify_joint_experiment(const Model& model, const std::vector<JointRecord>& runs,
                                         JointExperiment kind, int joint,
                                         const IdentifyOptions& options, const nlohmann::json& used,
                                         const ExperimentCompensation& compensation,
                                         std::vector<std::string>& warnings) {
  if (joint < 0 || joint >= model.dof()) {
    throw UsageError("--joint " + std::to_string(joint + 1) + " is not a joint of '" + model.name +
                     "'; give 1 to " + std::to_string(model.dof()));
  }
  std::vector<ProcessedRecord> processed;
  std::vector<std::pair<std::string, std::string>> choices;
  for (const JointRecord& record : runs) {
    if (record.q.cols() != model.dof()) {
      throw Error("a run has " + std::to_string(record.q.cols()) + " joints but model '" +
                  model.name + "' has " + std::to_string(model.dof()));
    }
    processed.push_back(preprocess(record, options.signal, choices));
  }
  const auto with_choices = [&](auto r) {
    r.choices.insert(r.choices.begin(), choices.begin(), choices.end());
    return r;
  };
  nlohmann::json result;
  if (kind == JointExperiment::kGravity) {
    GravityExperimentOptions go;
    go.confidence_level = options.confidence_level;
    if (count_distinct_poses(processed, joint, go) > 1) {  // the general form: over all q
      result = gravity_poses_to_json(
          model, with_choices(fit_gravity_poses(model, processed, joint, go)), used);
    } else {
      result = gravity_experiment_to_json(
          model, with_choices(fit_gravity_experiment(processed, joint, go)), used);
    }
  } else if (kind == JointExperiment::kFriction) {
    FrictionExperimentOptions fo;
    fo.confidence_level = options.confidence_level;
    Model compensated = model;
    if (compensation.result) {
      // A gravity or decoupled result compensates the gravity (and inertia) of this joint
      // (Bona & Curatella's chain); a base-parameter result the whole rigid body.
      add_stored_friction_compensation(model, *compensation.result, compensation.path, joint, fo);
      if (compensation.result->experiment.empty()) {
        CompletedModel c =
            completed_model_of_result(model, *compensation.result, compensation.path);
        for (const std::string& w : c.warnings)
          warnings.push_back("'" + compensation.path + "': " + w);
        compensated = std::move(c.model);
      }
    }
    result = friction_experiment_to_json(
        model, with_choices(fit_friction_experiment(compensated, processed, joint, fo)), used);
  } else {
    DecoupledModelOptions dm;
    dm.confidence_level = options.confidence_level;
    result = decoupled_model_to_json(model, with_choices(fit_decoupled_joint(processed, joint, dm)),
                                     used);
  }
  result["locked_joints"] = locked_joints_to_json(model);
  return result;
}

}  // namespace dynid
