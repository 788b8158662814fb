#pragma once

// Which parameters changed significantly between identifications of one robot (issue 31 item 3):
// per parameter the change, its standard deviation from both results' covariances, a z-score and
// a verdict at a family-wise false-alarm rate (Holm's step-down correction). The statistics are
// in docs/methods/fleet.md.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// One identification result to compare (the result JSON's `parameters` and
/// `covariance_matrix`).
struct DriftInput {
  std::string label;               ///< where it came from (file name), named in the output
  std::vector<std::string> names;  ///< parameter names
  Eigen::VectorXd values;          ///< estimates, one per name
  /// σ per name (NaN or inf where undetermined): the square roots of the covariance's diagonal,
  /// which is all a per-parameter comparison reads.
  Eigen::VectorXd std_devs;
};

/// What a parameter is, so that a maintenance engineer sees friction and payload changes apart.
enum class ParameterRole {
  kInertial,  ///< link inertial parameters (base combinations)
  kArmature,  ///< actuator inertias Ia, Iam
  kFriction,  ///< Fv, Fc, Fo and their asymmetric and coupled-motor forms
  kPayload,   ///< a gripped load's m, mcx … Izz (dynid payload)
};

/// "inertial", "armature", "friction" or "payload".
const char* to_string(ParameterRole role);

/// The role of a parameter from its name (ParameterLayout::names, the base set's R suffix,
/// load_identification's names).
ParameterRole parameter_role(const std::string& name);

/// Options of compare_estimates().
struct DriftOptions {
  /// Family-wise false-alarm rate: the probability that any parameter that did not change is
  /// flagged, over every test made (Holm 1979, valid whatever the dependence between tests).
  double alpha = 0.01;
};

/// One parameter of one later result against the baseline (the first input).
struct ParameterDrift {
  std::string name;
  ParameterRole role = ParameterRole::kInertial;
  int result = 0;       ///< index of the later input (1 …)
  double before = 0.0;  ///< baseline value
  double after = 0.0;   ///< later value
  double change = 0.0;  ///< after − before
  /// sqrt(σ_before² + σ_after²): the two identifications use independent data, so the variance
  /// of the difference is the sum of the two variances.
  double std_dev = 0.0;
  double z = 0.0;           ///< change / std_dev
  double p_value = 1.0;     ///< two-sided, standard normal: erfc(|z|/√2)
  double p_adjusted = 1.0;  ///< Holm-adjusted p-value over every test
  bool tested = false;      ///< false when a σ is not finite and positive (not in the family)
  bool flagged = false;     ///< tested and p_adjusted ≤ alpha
};

/// The comparison of every later input with the first.
struct DriftComparison {
  double alpha = 0.01;                  ///< DriftOptions::alpha
  int tests = 0;                        ///< size of the family (tested rows)
  std::vector<ParameterDrift> rows;     ///< per later input, per parameter in the baseline's order
  std::vector<std::string> not_shared;  ///< names missing from some input (not compared)
  /// Critical |z| a single test in a family of `tests` must exceed at the least (Bonferroni's
  /// level, alpha / tests; Holm's step-down flags the rest at lower levels).
  double first_critical_z = 0.0;
};

/// Compares inputs[1 …] with inputs[0] parameter by parameter (names present in every input).
/// Throws dynid::Error with fewer than two inputs, sizes that disagree with the names, or alpha
/// outside (0, 1).
DriftComparison compare_estimates(const std::vector<DriftInput>& inputs,
                                  const DriftOptions& options = {});

}  // namespace dynid
