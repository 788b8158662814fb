#pragma once

// A stored identification result applied again (issue 24 item 2): identify's options rebuilt from
// the result JSON's `options` and `choices`, the result's known friction added back, and the
// complete model of a result. The command line (validate, payload --reference, simulate --params,
// compare-control, identify --params) and the Python module call these, so both read a result the
// same way.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "dynid/common/error.hpp"
#include "dynid/experiments/friction_experiment.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/option_text.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/model/model.hpp"
#include "dynid/physical/completed_model.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/report/identification_report.hpp"

namespace dynid {

/// The `options` object a result JSON records, read with the file and key named in every error
/// (a wrong type is the file's fault, not a command-line flag's).
struct ResultFileOptions {
  const nlohmann::json& used;  ///< IdentifiedResultFile::options
  const std::string& path;     ///< the file (or "result"), named in errors
  /// options[key] as T; `fallback` when the key is absent. Throws dynid::Error naming the file and
  /// the key for a value of another type.
  template <typename T>
  T get(const char* key, const T& fallback) const {
    if (!used.contains(key)) return fallback;
    try {
      return used.at(key).get<T>();
    } catch (const nlohmann::json::exception&) {
      throw Error("'" + path + "': options." + key + " has the wrong type (" +
                  used.at(key).type_name() + "); give the result.json of dynid identify unedited");
    }
  }
};

/// A usage error raised by an option value read from result `path`: the same text with the flag
/// (--friction, --filter, --cutoff, --time-shift, --zero-velocity, --columns, --rate,
/// --torque-scale, --torque-bias) replaced by its key
/// (options.friction, ...), as a dynid::Error (the file is at fault, exit 1, not 2).
Error stored_option_error(const UsageError& e, const std::string& path);

/// What the caller sets instead of the stored result (validate's --cutoff, --zero-velocity and
/// run flags).
struct StoredOptionOverrides {
  std::optional<double> cutoff;       ///< low-pass cut-off [Hz]; unset: the one identify used
  std::vector<double> zero_velocity;  ///< per joint [rad/s]; empty: the thresholds identify used
  bool torque_scale_given = false;    ///< true: the caller's torque scale, not the stored one
  bool columns_given = false;         ///< true: the caller's --columns, not the stored ones
  bool rate_given = false;            ///< true: the caller's --rate, not the stored one
  bool torque_bias_given = false;     ///< true: the caller's --torque-bias, not the stored one
  bool topic_given = false;           ///< true: the caller's --topic, not the stored one
  std::optional<double> time_shift;   ///< [s]; unset: the time shift identify used
};

/// identify's options as a stored result rebuilds them (StoredIdentifyOptions).
struct StoredIdentifyOptions {
  /// The friction set and armature, filter, the cut-off identify used (choices.cutoff_hz, its
  /// automatic choice included), Savitzky–Golay, torque offset, filtered Coulomb columns and the
  /// zero-velocity thresholds identify used; everything else at identify's defaults.
  IdentifyOptions options;
  /// options.torque_scale as given to identify (empty when none, or when
  /// StoredOptionOverrides::torque_scale_given).
  std::vector<double> torque_scale;
  /// options.columns as given to identify, parsed (empty when none, or overridden): a log of the
  /// same recorder is read with the same renames (issue 26 item 3).
  ColumnMapping columns;
  double rate_hz = 0.0;  ///< options.rate_hz as given to identify (0 when none, or overridden)
  /// options.torque_bias as given to identify, parsed (empty when none, or overridden).
  std::vector<std::pair<std::string, double>> torque_bias;
  /// options.topic as given to identify: the ROS topic its log was read from (empty when none,
  /// or overridden).
  std::string topic;
  std::vector<std::string> notes;  ///< one line per value taken from the file

  /// Sets in `file` each of columns, rate, torque scale, bias and topic that the result stores and
  /// the caller did not override (a stored rate as not given: RunFileOptions::rate_given false).
  void apply_to(RunFileOptions& file) const;
};

/// Rebuilds identify's regressor and signal processing from `identified` (read from `path`) for a
/// run of a `dof`-joint robot, so that a prediction on another run compares the same kind of rows
/// as the fit, read with the same columns, rate, torque scale and bias. The friction set is
/// options.friction (text) or, in a Python result, options.viscous/coulomb/offset/asymmetric
/// (booleans); options.filter is text or a boolean. Throws dynid::Error naming `path` and the key
/// for a value of the wrong type or an invalid option in the file.
StoredIdentifyOptions options_of_stored_result(const IdentifiedResultFile& identified,
                                               const std::string& path, int dof,
                                               const StoredOptionOverrides& overrides = {});

/// A result identified with --friction-known stores that friction in options.known_friction: adds
/// it back to `names`/`values` and `options.layout` (append_known_friction), so that its
/// predictions are full torques. No change without it. Throws dynid::Error naming `path` for a
/// malformed list.
void add_stored_known_friction(const IdentifiedResultFile& identified, const std::string& path,
                               const Model& model, std::vector<std::string>& names,
                               Eigen::VectorXd& values, IdentifyOptions& options);

/// The complete model of a stored result (complete_identified_model()): its base parameters with
/// its friction set, armature and known friction, the parameters its data left undetermined or
/// badly determined at the nominal model's values, said in CompletedModel::warnings. Throws
/// dynid::Error naming `path` (an invalid option, a name that is no base parameter).
CompletedModel completed_model_of_result(const Model& model, const IdentifiedResultFile& identified,
                                         const std::string& path,
                                         const ModelCompletionOptions& completion = {});

/// What validate_torques() predicts with where a stored result leaves base parameters undetermined
/// and a run excites them (issue 25 item 2): the result completed with only its not excited
/// parameters at the nominal model's values (completed_model_of_result() with max_relative_std 0:
/// the badly determined but estimated ones keep their estimates, so a run like the identification
/// run is predicted exactly as before). Throws as completed_model_of_result().
ParameterCompletion nominal_completion_of_result(const Model& model,
                                                 const IdentifiedResultFile& identified,
                                                 const std::string& path);

/// The compensation a friction experiment of `joint` (0-based) takes from a stored result `path`
/// (Bona & Curatella's chain, seed 2 §3.2: the friction runs compensated with the gravity the
/// slopes identified): for a `--model gravity` result its gravity of the joint (k·sin(q_J + q_off)
/// or the base parameters over all q), for a `--model decoupled` result its gravity and
/// equivalent inertia; nothing for a base-parameter result (identify's, used through
/// completed_model_of_result()). Throws dynid::Error naming `path` for a result of another joint
/// or of a friction experiment.
void add_stored_friction_compensation(const Model& model, const IdentifiedResultFile& identified,
                                      const std::string& path, int joint,
                                      FrictionExperimentOptions& options);

/// `parameter_sources` of a JSON output: identified, nominal_not_excited,
/// nominal_badly_determined, max_shift_sigma (CompletedModel).
nlohmann::json parameter_sources_json(const CompletedModel& completed);

}  // namespace dynid
