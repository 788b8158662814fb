#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/identification/identify.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Options of complete_identified_model() (Ceres style).
struct ModelCompletionOptions {
  /// A combination of the estimated parameters is badly determined, and takes the nominal model's
  /// value, when its standard deviation exceeds this fraction of the parameters' scale (each
  /// scaled by max(|estimate|, |nominal value|), or its kind's magnitude where the nominal value is
  /// 0): the data do not fix even its order of magnitude (e.g. XX2R of a run in which joint 2's
  /// axis never changes orientation, or the two of four gravity parameters a one-joint run cannot
  /// separate). 0 or less: only the not excited ones are filled.
  double max_relative_std = 1.0;
};

/// An identified result turned into a complete model, and where each base parameter came from.
struct CompletedModel {
  Model model;                          ///< identified_model() of the completed base parameters
  std::vector<std::string> names;       ///< every base parameter (compute_base_parameters order)
  Eigen::VectorXd values;               ///< their completed values
  std::vector<std::string> identified;  ///< from the result (moved by the filled ones, below)
  std::vector<std::string> nominal_not_excited;  ///< not determined by the data: nominal
  /// Parameters that now hold mostly (> 50 %) the nominal value: badly determined combinations
  std::vector<std::string> nominal_badly_determined;
  int undetermined_directions = 0;  ///< badly determined combinations set to the nominal model
  /// Largest change of an identified parameter by the filling, relative to its σ (the data
  /// regroupings and its share of the filled directions); 0 when nothing was filled.
  double max_shift_sigma = 0.0;
  std::vector<std::string> warnings;  ///< one line per fact the user must know
};

/// Completes identified base parameters with the nominal model where the data do not determine
/// them, so that the model can be simulated and used in a controller (its mass matrix is that of
/// the nominal model in those directions instead of an undetermined number):
/// - not_excited parameters θ_u take the nominal base values θ_u⁰; each estimate is its base
///   parameter plus data_regrouping·θ_u (IdentificationResult::data_regrouping), so the
///   estimates become θ̂ − D·θ_u⁰, which predicts the identification data exactly as before;
/// - badly determined combinations: with z_i = θ_i/s_i, s_i = max(|θ̂_i|, |θ_i⁰|) (for θ_i⁰ = 0
///   also m_k, the median of |θ_j⁰| ≠ 0 over its kind on its link: second moments, first
///   moments, mass; friction: of max(|θ̂_j|, |θ_j⁰|) over the joints; a nominal 0 estimated
///   within σ of 0 is judged against its kind's magnitude), and the scaled
///   covariance C̃ = S⁻¹CS⁻¹ = VΛVᵀ, the eigen-directions V_U with √λ above
///   options.max_relative_std take the nominal model's component, z = ẑ + V_U·V_Uᵀ·(z⁰ − ẑ);
///   the others keep the estimate's. The eigen-directions are independent estimates (exactly so
///   for a white covariance C = σ²(WᵀW)⁻¹), and along V_U the data change the prediction by
///   little: ‖W·S·v‖ = σ/√λ (docs/methods/physical.md, "Completing a model"). Without
///   `covariance` (empty) only the not excited ones are filled and a warning says so.
/// `names`/`values` (size m) are the result's parameters; the first e of them were estimated, with
/// `std_devs` (size e ≤ m, NaN where unknown; e = 0: none is badly determined) and `covariance`
/// (e × e, or empty); names after them were appended as known (e.g. the known friction) and are
/// kept. `not_excited` are the result's undetermined parameters and `data_regrouping` its
/// (≤ m) × |not_excited| matrix (empty when there is none). options.layout is the result's.
/// Throws dynid::Error for a name that is not a base parameter of `nominal` with that layout,
/// and for sizes that do not match.
CompletedModel complete_identified_model(
    const Model& nominal, const std::vector<std::string>& names, const Eigen::VectorXd& values,
    const Eigen::VectorXd& std_devs, const std::vector<std::string>& not_excited,
    const Eigen::MatrixXd& data_regrouping, const Eigen::MatrixXd& covariance,
    const IdentifyOptions& options, const ModelCompletionOptions& completion = {});

}  // namespace dynid
