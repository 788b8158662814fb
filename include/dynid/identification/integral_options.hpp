#pragma once

#include "dynid/signal/integration.hpp"

namespace dynid {

/// Row weighting of the integral model: each row is divided by the relative standard deviation
/// of its error under one noise model, normalised to RMS 1 over the block (y stays in joules on
/// average). Measurements in docs/methods/identification.md, "Integral model".
enum class IntegralWeighting {
  kNone,  ///< rows as they are
  /// White torque noise: work of std ∝ √(Σ_k h_k²‖q̇_k‖²) over the interval's steps (fast
  /// intervals are noisier; unweighted OLS intervals then miss the truth).
  kTorqueNoise,
  /// Velocity noise at the interval ends entering the kinetic energy: std ∝
  /// √(Σ_j σ_q̇j²((M q̇)_a,j² + (M q̇)_b,j²)), M the mass matrix of the given (nominal) model with
  /// armature, σ_q̇ the processed record's velocity_noise_std. Falls back to kTorqueNoise when
  /// the record carries no velocity noise estimate (all zero or absent).
  kEndpointMomentum,
};

/// Options of integral_equations() (seed 1 eqs. 8–18, 32–35; docs/methods/identification.md,
/// "Integral model").
struct IntegralOptions {
  /// Interval length [s], rounded to a whole number of steps of the processed record; the run is
  /// cut into consecutive, non-overlapping intervals from its first sample (samples after the
  /// last whole interval are not used). 0 = kAutoIntervalSteps steps. Seed 1 used 5 ms at 0.5 ms
  /// sampling; 10 ms was among the best short intervals measured (docs/methods/identification.md,
  /// "Integral model"), and longer ones lost accuracy on the TX40 run.
  double interval = 0.01;
  /// Long integrals (seed 1 §IV): interval k runs from the first sample to the end of short
  /// interval k, i.e. the rows are running sums of the short ones.
  bool long_integrals = false;
  /// Quadrature of the actuator power τᵀq̇ (IntegrationRule). kZeroOrderHold integrates a torque
  /// held from one sample to the next exactly, as τ_kᵀ(q_{k+1} − q_k) (no velocity needed).
  IntegrationRule rule = IntegrationRule::kSimpson;
  /// How the short-integral rows are weighted (IntegralWeighting). Long rows share their start
  /// and are left unweighted.
  IntegralWeighting weighting = IntegralWeighting::kEndpointMomentum;
  /// Half-width [s] of the local quadratic fit of the processed positions that gives the
  /// velocities of the kinetic-energy columns at the interval ends; 0 = the processed velocity.
  double endpoint_window = 0.0;
};

}  // namespace dynid
