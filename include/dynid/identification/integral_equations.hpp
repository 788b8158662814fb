#pragma once

#include "dynid/estimation/equation_block.hpp"
#include "dynid/identification/integral_options.hpp"
#include "dynid/identification/record.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "dynid/signal/integration.hpp"

namespace dynid {

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
/// (exact when q is a cubic over the step), except that when `processed` carries the filtered
/// moving indicators p_j, n_j (ProcessedRecord::moving_positive/negative) the Coulomb columns are
/// ∫ q̇_j·(p_j − n_j) (asymmetric ∫ q̇_j·p_j, −∫ q̇_j·n_j) by options.rule: the Coulomb part of
/// the filtered power (parallel filtering); a coupled motor whose combination has a single joint
/// j with a velocity that is not identically zero on the run (the others held) then has the Fcm
/// column |n_kj| times that joint's ∫ q̇_j·(p_j − n_j), exactly the joint's Coulomb column up to
/// the factor, as u = n_kj·q̇_j (so the data-identifiability stage regroups the two). No
/// acceleration is used.
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
/// docs/methods/identification.md, "Integral model".
SignalOptions integral_signal_options();

}  // namespace dynid
