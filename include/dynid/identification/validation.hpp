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
  std::vector<std::pair<std::string, std::string>> choices;  ///< processing choices made
  ProcessedRecord processed;
  Eigen::MatrixXd predicted;  ///< samples × n predicted torques
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
/// exceeds that of the determined ones), the prediction would be a wrong number: Error naming the
/// parameters.
ValidationResult validate_torques(const Model& model, const JointRecord& record,
                                  const std::vector<std::string>& names,
                                  const Eigen::VectorXd& values, const IdentifyOptions& options,
                                  const std::vector<std::string>& not_excited = {});

}  // namespace dynid
