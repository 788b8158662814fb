#pragma once

#include "dynid/estimation/equation_block.hpp"
#include "dynid/estimation/identification.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/signal/integration.hpp"

namespace dynid {

/// Row weighting of the integral model: each row is divided by the relative standard deviation
/// of its error under one noise model, normalised to RMS 1 over the block (y stays in joules on
/// average). Measurements in docs/methods/estimation.md, "Integral model".
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

/// Options of integral_equations() (seed 1 eqs. 8–18, 32–35; docs/methods/estimation.md,
/// "Integral model").
struct IntegralOptions {
  /// Interval length [s], rounded to a whole number of steps of the processed record; the run is
  /// cut into consecutive, non-overlapping intervals from its first sample (samples after the
  /// last whole interval are not used). 0 = kAutoIntervalSteps steps. Seed 1 used 5 ms at 0.5 ms
  /// sampling; 10 ms was among the best short intervals measured (docs/methods/estimation.md,
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
};

/// Steps per interval when IntegralOptions::interval is 0 (the shortest interval on which
/// Simpson's rule is exact for cubics).
inline constexpr int kAutoIntervalSteps = 2;

/// The integral (energy) model of a processed run as a block of equations, one row per interval
/// [t_a, t_b] (seed 1 eqs. 10–17, 32–35):
///   y = ∫ τᵀq̇ dt = (h(t_b) − h(t_a))·θ + Σ_j friction work of joint j,
/// h the energy row of energy_regressor (link columns, armature ½·q̇_j²); friction columns
/// ∫ q̇_j² (Fv), ∫ |q̇_j| (Fc), ∫ q̇_j (Fo), asymmetric ∫ q̇_j²[q̇_j ≷ 0] (Fvp, Fvn) and
/// ∫ q̇_j[q̇_j > 0], −∫ q̇_j[q̇_j < 0] (Fcp, Fcn); with `coupling`, per coupled motor k with
/// u = n_k·q̇ (model/transmission.hpp, the velocity its friction acts on): Δ½(u² − Σ_j n_kj²q̇_j²)
/// (Iam), ∫ (u² − Σ_j n_kj²q̇_j²) (Fvm), ∫ |u| (Fcm). Columns are stacked_regressor_names(model,
/// layout, coupling), so base parameters and names are those of the differential model. The
/// power uses options.rule; the friction integrals use step_velocity_integrals on every step
/// (exact when q is a cubic over the step). No acceleration is used.
/// Units: y [J], columns [J per parameter unit] (times the row weight of options.weighting).
/// Block: ⌊(m − 1)/steps⌋ rows (m samples, `steps` per interval) × the named columns; group 0 =
/// "energy" for every row, sample = interval index, t = interval end [s]. Throws
/// dynid::UsageError for an interval shorter than one step (two samples) or longer than the run;
/// dynid::Error for a record whose sizes do not match the model, without torques, or in which no
/// joint moves beyond its position noise.
EquationBlock integral_equations(const Model& model, const ParameterLayout& layout, bool coupling,
                                 const ProcessedRecord& processed,
                                 const IntegralOptions& options = {});

/// Signal processing for the integral model (preprocess()): the differential defaults except a
/// fixed 10 Hz cut-off (the automatic rule, tuned for q̈, chose 1.1 Hz on a simulated run and the
/// filter's distortion of τᵀq̇ then dominated: 50 % torque error against 12 % at 10 Hz) and no
/// decimation (the power is integrated at the full rate). Measurements in
/// docs/methods/estimation.md, "Integral model".
SignalOptions integral_signal_options();

}  // namespace dynid
