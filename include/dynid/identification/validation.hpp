#pragma once

// Validation on another run (dynid validate): the torques an identified base model predicts,
// compared with the measured ones on the rows identify() would fit.

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/identification/identify.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Values to predict with where a result leaves base parameters undetermined (issue 25 item 2):
/// the completed base vector of the result (complete_identified_model() with only its not excited
/// parameters filled from the nominal model, report/stored_result.hpp:
/// nominal_completion_of_result()). Empty: no nominal value exists.
struct ParameterCompletion {
  std::vector<std::string> names;  ///< base parameter names (as identify() names them)
  Eigen::VectorXd values;          ///< their completed values, same order
};

/// Per-joint prediction error of identified base parameters on another record (dynid validate).
/// Two figures: over every row (the headline), and over the rows identify() fits (near-still rows
/// of a Coulomb model left out: their sign(dq) is noise).
struct ValidationResult {
  Eigen::VectorXd rms;              ///< per joint [N·m], on the rows compared
  Eigen::VectorXd relative_error;   ///< per joint ‖e_j‖/‖tau_j‖, on the rows compared
  double relative_error_all = 0.0;  ///< ‖e‖/‖tau‖ over all joints, on the rows compared
  /// ‖e‖/‖tau‖ over every sample, near-zero-velocity rows included.
  double relative_error_all_rows = 0.0;
  Eigen::VectorXd rms_all_rows;                   ///< per joint [N·m], every sample
  Eigen::VectorXd relative_error_all_rows_joint;  ///< per joint ‖e_j‖/‖tau_j‖, every sample
  Eigen::VectorXd zero_velocity_threshold;  ///< per joint, the |dq_j| below which rows are left out
  Eigen::VectorXi joint_rows_excluded;      ///< per joint, rows left out by that threshold
  Eigen::Index samples = 0;                 ///< samples after preprocessing
  Eigen::Index rows = 0;           ///< joint equations compared (samples × joints − excluded)
  Eigen::Index rows_excluded = 0;  ///< near-zero-velocity rows left out, as identify() does
  /// Per joint, the |dq_j| below which a row counts as still [rad/s or m/s]: max(v_c,j, 3·σ_dq,j),
  /// inside the Coulomb law's transition band (its term below erf(1/√2) = 68 % of Fc) or the
  /// velocity noise. Still rows are predicted (with the smooth law) and kept in every figure
  /// above; the split below only reports how well rest is predicted.
  Eigen::VectorXd still_threshold;
  Eigen::VectorXi joint_rows_still;         ///< per joint, rows below still_threshold
  double relative_error_still_rows = 0.0;   ///< ‖e‖/‖tau‖ over the still rows (0 if none)
  double relative_error_moving_rows = 0.0;  ///< ‖e‖/‖tau‖ over the other rows (0 if none)
  std::vector<std::pair<std::string, std::string>> choices;  ///< processing choices made
  ProcessedRecord processed;
  Eigen::MatrixXd predicted;  ///< samples × n predicted torques
  /// Parameters the result does not determine but this record excites, predicted at their
  /// nominal values (ParameterCompletion); empty when the result's own estimates sufficed.
  std::vector<std::string> completed;
  /// ‖τ̂ − τ̂_estimates‖/‖τ̂‖ over every row: the share of the predicted torque that the filled
  /// values carry, (W_u − W_k·D)·θ_u⁰ against W·θ (0 when nothing was filled).
  double filled_share = 0.0;
  std::vector<std::string> warnings;  ///< one line per fact the user must know
};

/// Predicts the torques of `record` with base parameters `values` named `names` (as identify()
/// wrote them) and compares. The record is preprocessed and, with Coulomb friction in the layout,
/// rows with |dq_j| below the zero-velocity threshold are left out of the statistics exactly as
/// identify() leaves them out of the fit (so validating on the identification run reproduces its
/// relative error); relative_error_all_rows keeps them. The thresholds are options.signal
/// .zero_velocity (give the identification's IdentificationResult::zero_velocity_threshold), else
/// the automatic rule of identify() on this record. A name that is not a column of the model
/// and layout is an Error naming the parameter.
/// `not_excited` are the base parameters the identification data did not determine
/// (IdentificationResult::not_excited): the estimates then hold data regroupings that predict only
/// motions which leave those directions unexcited too. When this record excites a direction the
/// result does not determine (the data rank of its determined and undetermined columns together
/// exceeds that of the determined ones), the estimates alone would predict a wrong number: the
/// record is then predicted with `nominal` (the estimates moved by −D·θ_u⁰ and θ_u = θ_u⁰, which
/// predicts the identification data exactly as the estimates do), `completed` and
/// `filled_share` say what was filled and how much of the prediction it carries, with a warning.
/// Error naming the parameters only when `nominal` is empty (no nominal value exists).
ValidationResult validate_torques(const Model& model, const JointRecord& record,
                                  const std::vector<std::string>& names,
                                  const Eigen::VectorXd& values, const IdentifyOptions& options,
                                  const std::vector<std::string>& not_excited = {},
                                  const ParameterCompletion& nominal = {});

}  // namespace dynid
