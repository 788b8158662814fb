#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

struct IdentificationResult;
struct IdentifyOptions;
struct JointRecord;

/// Options of physical_parameters() (Ceres style).
struct PhysicalFitOptions {
  /// Level of the χ² test that decides whether a physically consistent set fits the estimate: the
  /// squared Mahalanobis distance of its base combination from the estimate is compared with the
  /// χ²(rank) quantile at this level. Above it, Error (no consistent solution near the data).
  double confidence_level = 0.999;
  /// Weight of the pull towards the nominal standard parameters (relative deviations, summed in
  /// squares), against the data term in units of σ². Small: it only chooses among the standard
  /// sets with the same base combination (the unidentifiable directions).
  double prior_weight = 1e-8;
  /// Smallest second moment of the mass about the centre of mass per axis [m²] given to a nominal
  /// link whose inertia is degenerate (a slender rod, a point mass) to start the log-Cholesky
  /// parametrisation, which is strictly positive definite.
  double min_second_moment = 1e-6;
  int max_iterations = 500;  ///< Levenberg–Marquardt iterations (Ceres)
  /// Stop when the last `stall_window` iterations together lowered the cost by less than this
  /// fraction of it. Along the valley of the unidentifiable directions the steps only trade the
  /// weak prior against itself: on the TX40 run 4500 more iterations moved the Mahalanobis
  /// distance by 0.01 σ (docs/performance.md).
  double stall_tolerance = 1e-5;
  int stall_window = 25;  ///< iterations over which stall_tolerance is measured
  /// Refuse (Error) a nearest consistent set farther than the χ² limit. Off by default: real data
  /// always carry some model mismatch, so the nearest set is returned with
  /// PhysicalFit::within_limit false, for the caller to warn (issue 25 item 6).
  bool refuse_beyond_limit = false;
};

/// A physically consistent standard parameter set fitted to identified base parameters.
struct PhysicalFit {
  std::vector<std::string> names;  ///< standard parameter names (layout, then coupling columns)
  Eigen::VectorXd theta;           ///< standard parameters, docs/design.md §3 order
  Eigen::VectorXd theta_b;         ///< their base combination θ_1 + K_d·θ_2
  /// √((θ_b − θ̂_b)ᵀ C⁻¹ (θ_b − θ̂_b)): how far the consistent set is from the estimate [σ].
  double mahalanobis = 0.0;
  double chi2_limit = 0.0;  ///< √ of the χ²(estimated parameters) quantile at confidence_level
  bool within_limit = false;  ///< mahalanobis ≤ chi2_limit: the data accept the consistent set
  double nominal_distance = 0.0;  ///< ‖θ − θ_nominal‖/‖θ_nominal‖ over the link parameters
  /// Per link, the smallest eigenvalue of the pseudo-inertia J (> 0: physically consistent)
  /// [kg·m²].
  Eigen::VectorXd min_pseudo_inertia_eigenvalue;
  bool consistent = false;  ///< every link J ≻ 0 and every friction/armature term ≥ 0
  int iterations = 0;       ///< Levenberg–Marquardt iterations
  /// Ceres reported convergence, or the cost stalled (PhysicalFitOptions::stall_tolerance)
  bool converged = false;
};

/// Standard parameters per link that are physically realisable (mass > 0, pseudo-inertia J ≻ 0,
/// which is the triangle inequalities of the principal moments; Ia, Fv, Fc ≥ 0) and whose base
/// combination fits identified base parameters theta_b (covariance C) as closely as possible,
/// nearest the nominal model where the data leave freedom. Each link's J = U·Uᵀ with U upper
/// triangular in the log-Cholesky parametrisation of Rucker & Wensing (2022), so every iterate is
/// consistent; the nonnegative joint terms are squares; coupled-motor columns are free. Minimises
/// ‖L⁻¹(θ_b(φ) − θ̂_b)‖² + prior_weight·Σ((θ_i − θ_nom,i)/s_i)² (C = L·Lᵀ) by Levenberg–
/// Marquardt (Ceres) from the nominal model. `base`: compute_base_parameters() of `nominal` with
/// `layout` (and coupling as in the identification). Throws dynid::Error for sizes that do not
/// match, a covariance that is not positive definite, a nominal model without mass on any moving
/// link (nothing to stay close to), and when no consistent set lies within the χ² limit (the
/// message says how far, in σ).
/// `observed` (k × rank, or empty for the identity): what the estimate measures of the base
/// vector, θ̂ ≈ observed·θ_b(θ) with `covariance` k × k. A result whose data leave base
/// parameters not excited estimates the kept ones plus their data regrouping, observed =
/// [selection of the kept] + D·[selection of the not excited]; the not excited directions then
/// follow the pull towards the nominal model. PhysicalFit::theta_b is the whole base vector.
PhysicalFit physical_parameters(const Model& nominal, const BaseParameters& base,
                                const ParameterLayout& layout, const Eigen::VectorXd& theta_b,
                                const Eigen::MatrixXd& covariance,
                                const PhysicalFitOptions& options = {},
                                const Eigen::MatrixXd& observed = Eigen::MatrixXd());

/// physical_parameters() of an identification's estimate, with the relative torque error
/// ‖τ − τ̂‖/‖τ‖ over every row of `run` of the consistent set and of the free estimate.
struct PhysicalCheck {
  PhysicalFit fit;                    ///< the consistent set
  double physical_error = 0.0;        ///< torque error of fit.theta_b on the run
  double free_error = 0.0;            ///< torque error of the identified estimate on the run
  std::vector<std::string> warnings;  ///< one line per fact the user must know
};

/// The consistent set of `result` (identify() of `model` with `options`) and both torque errors
/// on `run` (validate_torques() with identify's cut-off, result.processed.cutoff_hz), as
/// `identify --physical` and the Python physical=True report them. `free_error`: the free
/// estimate's error when the caller already validated it on `run` (else computed). `option`
/// names the request in messages ("--physical", "physical=True"). Base parameters the data did
/// not excite are fitted through their data regroupings (physical_parameters()' `observed`) and
/// take the consistent set's values nearest the nominal model. `warnings` says when the nearest
/// consistent set lies beyond the χ² limit. Throws as physical_parameters() (a fit that fails)
/// and validate_torques().
PhysicalCheck physical_parameters_of_result(const Model& model, const IdentificationResult& result,
                                            const IdentifyOptions& options, const JointRecord& run,
                                            const std::string& option,
                                            std::optional<double> free_error = std::nullopt);

/// The 4×4 pseudo-inertia J = [[Σ, h], [hᵀ, m]] of standard link parameters (XX XY XZ YY YZ ZZ MX
/// MY MZ M about the link origin): Σ = ½tr(I)·𝟙 − I, h = (MX, MY, MZ). J ≻ 0 exactly when the
/// link is physically realisable with a positive mass (Wensing, Kim & Slotine 2017).
Eigen::Matrix4d pseudo_inertia(const Eigen::Ref<const Eigen::VectorXd>& link);

}  // namespace dynid
