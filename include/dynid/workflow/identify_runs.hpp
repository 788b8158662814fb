#pragma once

// `dynid identify` after its files are read (issue 29 item 3): the estimate of one or several
// runs with every stage the command line adds around identify() (repeated estimates, the plots of
// a report, the physically consistent fit) and the dedicated one-joint experiments, each with its
// result JSON. The command line and the Python module both call these, so that their results
// cannot drift apart.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynid/closed_loop/closed_loop.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/model/model.hpp"
#include "dynid/physical/physical_parameters.hpp"
#include "dynid/report/identification_report.hpp"

namespace dynid {

/// What identify_runs() does besides identify(): the command line's identify flags that are no
/// IdentifyOptions field.
struct IdentifyRunsOptions {
  /// "periods" or "runs": also identify each whole period (or each run) alone and report the
  /// spread of the estimates (seed 2 §3.5, Table 3); empty: not.
  std::string repeat;
  /// Also fit physically consistent standard parameters to the estimate (log-Cholesky, Rucker and
  /// Wensing 2022; physical_parameters_of_result()).
  bool physical = false;
  /// How the caller names the physical request in messages ("--physical", "physical=True").
  std::string physical_option = "--physical";
};

/// An identification as `dynid identify` writes it.
struct IdentifiedRuns {
  IdentificationResult result;               ///< identify()'s (or identify_stream()'s)
  std::optional<RepeatedEstimate> repeated;  ///< with IdentifyRunsOptions::repeat
  std::optional<PhysicalCheck> physical;     ///< with IdentifyRunsOptions::physical
  /// The result JSON (identification_to_json() plus closed_loop, repeated, plot, physical).
  nlohmann::json json;
  /// One line per fact the user must know that is no error (a plot left out, a physical fit
  /// beyond its χ² limit); the command line prints them as warnings.
  std::vector<std::string> warnings;
};

/// identify() of `runs` (with `references`, one per run, for a closed-loop preparation or a
/// repeat over periods; else empty), and with IdentifyRunsOptions::repeat the repeated estimates
/// (identify_repeated()), whose checks run before the whole-run estimate. The JSON is left empty
/// (identified_runs_to_json()). Throws dynid::Error as repeated_pieces() and identify() do, and
/// dynid::UsageError for a repeat that is neither "periods" nor "runs".
IdentifiedRuns identify_runs(const Model& model, const std::vector<JointRecord>& runs,
                             const std::vector<ReferenceRecord>& references,
                             const IdentifyOptions& options,
                             const IdentifyRunsOptions& run_options);

/// Fills out.json (and out.physical, out.warnings) as `dynid identify` writes its result:
/// identification_to_json() with `used` (the options as given, completed with
/// filter_coulomb_columns and known_friction, which validate reads back), `closed_loop` with a
/// closed-loop preparation, `repeated`, and `plot`: the first run's measured and predicted torques
/// (validate_torques() at identify's cut-off), the RLS history, the integral model's energy. With
/// IdentifyRunsOptions::physical, the consistent standard parameters measured on the first run, or
/// on `physical_run` when `runs` is empty (the streaming mode keeps no run). Throws as
/// physical_parameters_of_result(); a plot that cannot be made is a warning, not an error.
void identified_runs_to_json(const Model& model, const std::vector<JointRecord>& runs,
                             const IdentifyOptions& options, const IdentifyRunsOptions& run_options,
                             nlohmann::json used, IdentifiedRuns& out,
                             const JointRecord* physical_run = nullptr);

/// Seed 2's dedicated experiments on one joint (identify --model gravity|friction|decoupled).
enum class JointExperiment {
  kGravity,   ///< constant-velocity slopes (gravity_experiment.hpp)
  kFriction,  ///< bang-bang moves, inertia and gravity compensated (friction_experiment.hpp)
  kDecoupled  ///< one joint moving, the others held (decoupled_model.hpp)
};

/// "gravity", "friction" or "decoupled" as a JointExperiment; throws dynid::UsageError otherwise.
JointExperiment joint_experiment_of(const std::string& name);

/// The compensation of a friction experiment: a stored result and the name it is known by.
struct ExperimentCompensation {
  const IdentifiedResultFile* result = nullptr;  ///< none: the robot's nominal model
  std::string path;                              ///< the file (or "params"), named in messages
};

/// The experiment of joint `joint` (0-based) from `runs`, each preprocessed with options.signal,
/// fitted by least squares at options.confidence_level, as the result JSON of `dynid identify
/// --model KIND` (gravity: over all q when the runs hold the other joints at two poses or more;
/// friction: compensated with `compensation`, its rigid body or the gravity or decoupled result of
/// the same joint), with `used` as its options and locked_joints. `warnings` receives what the
/// compensation filled from the nominal model. Throws dynid::UsageError for a joint out of range
/// and dynid::Error as the fits do.
nlohmann::json identify_joint_experiment(const Model& model, const std::vector<JointRecord>& runs,
                                         JointExperiment kind, int joint,
                                         const IdentifyOptions& options, const nlohmann::json& used,
                                         const ExperimentCompensation& compensation,
                                         std::vector<std::string>& warnings);

}  // namespace dynid
