#pragma once

#include <Eigen/Core>

namespace dynid {

/// Quadrature rule for a sampled function over a run of consecutive samples.
enum class IntegrationRule {
  kTrapezoid,  ///< ½·h·(f_k + f_{k+1}) per step: exact for degree ≤ 1
  /// Simpson on pairs of steps (non-uniform form); an odd last step takes the quadratic through
  /// the last three samples. Exact for degree ≤ 2 always, degree ≤ 3 on uniform steps with an
  /// even step count.
  kSimpson,
  /// f_k·h per step (the value held from t_k to t_{k+1}): exact for a zero-order-hold signal, as
  /// a digital controller applies its torque command.
  kZeroOrderHold,
};

/// ∫ f dt from t[first] to t[last] over the samples in between (first < last), by `rule`.
/// t: strictly increasing [s]; f: same size. Identity: see IntegrationRule. No allocation.
/// Throws dynid::Error for first ≥ last, indices outside t, or a size mismatch.
double integrate_samples(const Eigen::Ref<const Eigen::VectorXd>& t,
                         const Eigen::Ref<const Eigen::VectorXd>& f, Eigen::Index first,
                         Eigen::Index last, IntegrationRule rule);

/// Integrals of a velocity over one step of length h > 0 [s] between two samples, from the
/// positions' difference dx = x(h) − x(0) and the end velocities v0, v1: v(s) is the quadratic
/// with v(0) = v0, v(h) = v1 and ∫₀ʰ v = dx (exact when x is a cubic over the step), split where
/// it changes sign. Used for friction work (seed 1 eqs. 15–17), whose integrands |v|, v² and the
/// per-direction parts have kinks at v = 0 that a sampled rule would smear.
struct StepVelocityIntegrals {
  double positive = 0.0;         ///< ∫ max(v, 0) ds [rad or m]
  double negative = 0.0;         ///< ∫ min(v, 0) ds (≤ 0)
  double positive_square = 0.0;  ///< ∫ v²·[v > 0] ds [rad²/s or m²/s]
  double negative_square = 0.0;  ///< ∫ v²·[v < 0] ds
};
StepVelocityIntegrals step_velocity_integrals(double h, double dx, double v0, double v1);

}  // namespace dynid
