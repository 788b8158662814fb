#pragma once

#include <cstddef>
#include <string>

#include <nlohmann/json.hpp>

#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/model/model.hpp"
#include "dynid/sim/simulation_validation.hpp"

namespace dynid {

/// The result JSON of docs/design.md §4 / issue 4: model summary, `parameters` (name, value, std,
/// relative_std_percent, ci_low, ci_high, expression), `confidence_level`, `rank`,
/// `condition_number`, `samples`, `rows`, `residual_rms` and `joint_relative_error` per joint,
/// `relative_error`, `unidentifiable`, `warnings`, `choices` (every processing decision), `options`
/// as given and `version`. Non-finite numbers become null.
nlohmann::json identification_to_json(const Model& model, const IdentificationResult& result,
                                      const nlohmann::json& options_used);

/// A readable table: name, value, σ, %σ, confidence interval; then rank, condition number and the
/// per-joint residuals and warnings.
std::string identification_table(const Model& model, const IdentificationResult& result);

/// What `dynid validate` takes from a result JSON written by identification_to_json.
struct IdentifiedResultFile {
  std::vector<std::string> names;   ///< base parameter names, in file order
  Eigen::VectorXd values;           ///< their values
  nlohmann::json options;           ///< `options` as given to identify (empty object if absent)
  std::string robot;                ///< `model.name`; empty when the file has none
  std::vector<std::string> joints;  ///< `model.joints`; empty when the file has none
  /// `locked_joints`: the robot file's joints identify held fixed (empty: none, or an older file).
  std::vector<JointLock> locked_joints;
  /// `zero_velocity_threshold` per joint as identify used it; empty in files written before it
  /// was stored.
  std::vector<double> zero_velocity_threshold;
  /// `coulomb_width` per joint, the smooth Coulomb law's transition velocity identify used
  /// [rad/s or m/s]; empty in files written before it was stored (the sign law then).
  std::vector<double> coulomb_width;
  /// `choices.cutoff_hz`, the low-pass cut-off identify used [Hz]; 0 when absent (no filter, or
  /// a file written before it was stored).
  double cutoff_hz = 0.0;
  /// `not_excited`: base parameters the identification data did not determine (empty in files
  /// written before it was stored).
  std::vector<std::string> not_excited;
  /// `parameters[].std` (NaN where absent or null), `covariance_matrix` (names × names) and
  /// `data_regrouping` (names × not_excited, IdentificationResult::data_regrouping); the matrices
  /// are empty in files written before they were stored.
  Eigen::VectorXd std_devs;
  Eigen::MatrixXd covariance, data_regrouping;
  /// `experiment` of a dedicated-experiment result (gravity, friction, decoupled) and its 1-based
  /// `joint`; empty and 0 for identify's base-parameter results.
  std::string experiment;
  int experiment_joint = 0;
};

/// Largest result JSON the readers take (read_identification_result, dynid report --in): a result
/// with its plots is a few MB; a larger file is not one dynid wrote.
inline constexpr std::size_t kMaxResultFileBytes = std::size_t{256} << 20;

/// Reads a result JSON (identification_to_json). Throws dynid::Error naming the file when
/// `parameters` is missing or malformed, or a stored threshold is not a non-negative number.
IdentifiedResultFile read_identification_result(const std::string& path);

/// read_identification_result of a parsed result (the Python module's dicts); `path` names it in
/// the messages.
IdentifiedResultFile identification_result_from_json(const nlohmann::json& j,
                                                     const std::string& path);

/// Reads `parameters[].name/value` and `options` of a result JSON (read_identification_result).
void read_identified_parameters(const std::string& path, std::vector<std::string>& names,
                                Eigen::VectorXd& values, nlohmann::json& options_used);

/// The base-parameter section of `dynid model --base`: `base_parameters` (name, expression),
/// `unidentifiable`, `rank`, and the text version.
nlohmann::json base_parameters_to_json(const BaseParameters& base);
std::string base_parameters_text(const BaseParameters& base);

/// `dynid validate` JSON: `joints` (name, rms, relative_error on the rows compared; rms_all_rows,
/// relative_error_all_rows, rows_left_out), `relative_error` (rows compared: near-still rows left
/// out as identify did), `relative_error_all_rows` (every row), `samples`, `rows`,
/// `rows_excluded_zero_velocity`, `rows_left_out` {rule, zero_velocity_threshold, rows},
/// `choices`, `version`.
nlohmann::json validation_to_json(const Model& model, const ValidationResult& v);

/// The validation table: per joint RMS and relative error over every row, relative error over the
/// moving rows and rows left out; then the error over every row (headline) and, when rows were
/// left out, the error without them, labelled.
std::string validation_table(const Model& model, const ValidationResult& v);

/// `dynid validate --predicted`: CSV with `t` and, per joint j (1-based), `tau<j>` (measured,
/// after the same filtering as identify), `tau_pred<j>` (predicted), `residual<j>` = tau − tau_pred
/// [N·m], and `left_out<j>` (1 where |dq_j| is below the zero-velocity threshold, i.e. the row is
/// left out of the near-still-free error, else 0), one line per processed sample. Written
/// atomically; throws dynid::Error as write_csv.
void write_validation_predictions(const std::string& path, const ValidationResult& v);

/// Writes the RLS history of an identification (IdentifyOptions::record_history) as CSV: `t`, then
/// per parameter NAME its value and NAME_std, one line per equation from the first with a residual
/// degree of freedom (σ is undefined before). Throws dynid::Error when the result has no history.
void write_rls_history(const std::string& path, const IdentificationResult& r);

/// `dynid validate --mode simulation` JSON: `joints` (name, position {rms, max, mean, std,
/// skewness, kurtosis, ks_statistic, ks_p_value}, torque {same}), `samples`, `version`.
nlohmann::json simulation_validation_to_json(const Model& model, const SimulationValidation& v);
std::string simulation_validation_table(const Model& model, const SimulationValidation& v);

}  // namespace dynid
