#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// Which regressor is sampled to find the base parameters.
enum class BaseRegressor {
  kTorque,  ///< the differential model Y(q, dq, ddq) (seed 1 eq. 5)
  kEnergy,  ///< differences of the energy row h(q, dq) (seed 2 eqs. 4–8); friction columns have
            ///< no energy, so only the link and armature columns are classified from it
};

/// How compute_base_parameters finds the base parameters.
enum class BaseAlgorithm {
  kAuto,   ///< kTree for the torque regressor without coupled motors, else kDense
  kDense,  ///< left-to-right sweep over the whole sampled regressor: O(n³) time, O(n²) memory
  kTree,   ///< null space from local systems of each link and its parent: O(n) sampling, O(n²)
           ///< only for K_d (docs/methods/model.md, "Base parameters of large trees")
};

/// Options of the numerical base-parameter computation.
struct BaseParameterOptions {
  ParameterLayout layout;  ///< columns to classify (link + per-joint terms)
  bool coupling =
      false;  ///< append the coupled-motor columns (model/transmission.hpp), torque only
  BaseRegressor regressor = BaseRegressor::kTorque;  ///< which model is sampled
  BaseAlgorithm algorithm = BaseAlgorithm::kAuto;    ///< same result either way (tested)
  int samples = 0;  ///< random states; 0 = 40 (tree) or max(100, 4·columns/n + 50) (dense)
  unsigned seed = 20261123;       ///< fixed seed: the same model gives the same base set every time
  double zero_tolerance = 1e-10;  ///< column norm / largest column norm below this: no effect
  double dependence_tolerance = 1e-8;  ///< residual / own norm below this: linearly dependent
  /// Threshold pivoting of the regrouping: in units of columns scaled to unit norm, a column is
  /// made dependent only where its null vector gives it at least this weight; otherwise it trades
  /// places with the base column of highest index that has it (docs/methods/model.md,
  /// "Well-conditioned base columns"). Keeps the base columns well conditioned when a joint axis
  /// is nearly, not exactly, along a frame axis; changes nothing where Gautier's rule already
  /// pivots on weights above it (every built-in robot). 0 = Gautier's rule alone.
  double pivot_threshold = 0.1;
  double coefficient_digits = 6;  ///< significant digits of K_d in the expressions
  double max_seconds = 0.0;  ///< wall-clock limit [s]; 0 = none; beyond it dynid::Error is thrown
};

/// The base (identifiable) parameters: theta_b = theta_1 + K_d·theta_2 (Gautier–Khalil 1990).
struct BaseParameters {
  int rank = 0;                           ///< number of base parameters
  std::vector<int> base;                  ///< indices (into the layout) of theta_1, increasing
  std::vector<int> dependent;             ///< indices of theta_2 (regrouped into the base ones)
  std::vector<int> unidentifiable;        ///< indices with no effect at all (seed 2 eq. 6)
  Eigen::MatrixXd K_d;                    ///< base.size() × dependent.size()
  std::vector<std::string> names;         ///< base parameter names, `R` suffix when regrouped
  std::vector<std::string> expressions;   ///< `ZZ2R = ZZ2 + 0.2025*M3 + YY3`
  std::vector<std::string> layout_names;  ///< names of every layout column
  int samples = 0;                        ///< random states used
  BaseAlgorithm algorithm = BaseAlgorithm::kDense;  ///< the algorithm that produced it

  /// theta_b = theta_1 + K_d·theta_2 for a full layout vector theta.
  Eigen::VectorXd reduce(const Eigen::Ref<const Eigen::VectorXd>& theta) const;
  /// The base regressor W_b = W_1 + 0 (the base columns of W): since W_2 = W_1·K_d, W·theta =
  /// W_b·theta_b.
  Eigen::MatrixXd select(const Eigen::Ref<const Eigen::MatrixXd>& W) const;
  /// Names of the standard parameters that have no effect (unidentifiable).
  std::vector<std::string> unidentifiable_names() const;
};

/// Numerical base parameters (Gautier 1990, "Numerical calculation of the base inertial parameters
/// of robots"): sample the regressor at random states, keep the columns that are independent of the
/// columns before them (a left-to-right rank-revealing sweep, so each base parameter is named after
/// the earliest standard parameter it contains, as in Khalil's regrouping rules), and solve
/// W_2 = W_1·K_d by least squares. Deterministic for a given model and options. For the torque
/// regressor the same classification comes from the tree structure in near-linear time
/// (BaseAlgorithm::kTree, the default there). Throws dynid::Error if the model has no identifiable
/// parameter, when options.max_seconds runs out, and when the dense sweep would need more than
/// 2 GB.
BaseParameters compute_base_parameters(const Model& model,
                                       const BaseParameterOptions& options = {});

/// The nominal model's value of every base parameter: θ_b⁰ = θ_1⁰ + K_d·θ_2⁰ (Gautier–Khalil), θ⁰
/// the model's own standard parameters in `layout` (ParameterLayout::parameters(), coupled-motor
/// columns 0), in base.names order and units. A base parameter led by a per-joint column (Ia, Fv,
/// Fc, Fo, a coupled motor's Coulomb) whose model value is 0 has no nominal value (std::nullopt):
/// a URDF has no field for rotor inertia or offsets, and an absent <dynamics> is no friction
/// estimate. Throws dynid::Error when `base` was not computed for `model` with `layout`.
std::vector<std::optional<double>> nominal_base_values(const Model& model,
                                                       const BaseParameters& base,
                                                       const ParameterLayout& layout);

/// Classifies the columns of a given sampled regressor W (rows = equations) the same way; used by
/// compute_base_parameters and by the identification on real data to report unexcited columns.
BaseParameters classify_columns(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const std::vector<std::string>& names,
                                const BaseParameterOptions& options);

}  // namespace dynid
