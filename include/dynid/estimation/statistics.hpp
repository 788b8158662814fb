#pragma once

#include <Eigen/Core>

#include "dynid/estimation/estimate.hpp"

namespace dynid {

/// Two-sided Student-t quantile: returns t with P(|T| ≤ t) = level for T ~ t(dof).
/// Used for the confidence intervals x ± t·σ_x of seed 2 Table 3. Boost.Math.
/// Throws dynid::Error if level ∉ (0, 1) or dof ≤ 0.
double student_t_quantile(double level, double dof);

/// Fills the parameter statistics of `estimate` from its x, covariance and degrees_of_freedom:
/// std_dev = sqrt(diag C), relative_std_percent = 100·σ_x/|x|, Student-t intervals at
/// options.confidence_level with degrees_of_freedom, and the poorly excited list (relative σ
/// above options.poorly_excited_percent). Columns listed in estimate.unidentifiable get infinite σ.
/// When degrees_of_freedom ≤ 0 the statistics are NaN and a warning is added.
/// Throws dynid::Error if options.confidence_level ∉ (0, 1).
void fill_parameter_statistics(Estimate& estimate, const EstimationOptions& options);

}  // namespace dynid
