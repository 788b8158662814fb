#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/closed_loop/closed_loop_options.hpp"
#include "dynid/closed_loop/projection.hpp"
#include "dynid/estimation/equation_block.hpp"
#include "dynid/estimation/estimate.hpp"
#include "dynid/identification/identify.hpp"

namespace dynid {

/// A closed-loop run prepared for identification, and the operator it was prepared with.
struct ClosedLoopRun {
  /// q̂, q̂', q̂'', û on the kept samples; position_noise_std = std of q − q̂ per joint.
  ProcessedRecord processed;
  /// The same projection for the regressor columns (project_equations).
  std::shared_ptr<const SignalProjector> projector;
  ClosedLoopReport report;  ///< what was chosen and found
  /// Per joint std of τ − τ̂ on the kept samples [N·m or N]: the torque noise the projection
  /// removes (maximum likelihood's torque noise after a projection when none is given).
  Eigen::VectorXd torque_remainder_std;
  /// What the user should know about the preparation (identify() adds them to the result's
  /// warnings): a FIR order whose remainder fails the test, a reference dimension it cannot keep.
  std::vector<std::string> warnings;
};

/// The prepare stage of closed-loop identification. Projection: project_on_reference() with the
/// reference's derivatives as given, else derived from qr (exactly, by its Fourier series, when
/// qr is periodic to 1e-9 of its range; else by central differences of the noise-free qr).
/// The projection's automatic FIR order also keeps the 2L + 1 dimensions of a periodic
/// reference with L lines (ProjectionOptions::min_rank, seed 2 eqs. 10–12).
/// A joint whose reference is constant (held: seed 2 section 3's one-joint runs) is taken as still
/// by both methods (dq, ddq zero; ClosedLoopReport::held_joints).
/// Spectral: the last whole periods of the run (period detected from qr, exact to 1e-9), q and τ
/// kept on the harmonics 0…H of f0 (H = the reference's highest line), q̂' and q̂'' by iω and −ω²
/// on those lines (no finite difference). run: t uniform [s], q, tau m × n; dq, ddq ignored.
/// Processing choices are appended to `choices`. Throws dynid::Error for no or mismatched
/// reference columns, every reference constant, a reference that is not periodic (spectral),
/// fewer than two whole periods, and as project_on_reference().
ClosedLoopRun prepare_closed_loop(const JointRecord& run, const ReferenceRecord& reference,
                                  const ClosedLoopIdOptions& options,
                                  std::vector<std::pair<std::string, std::string>>& choices);

/// The equations projected like the signals (Gautier's parallel filtering with P for the
/// filter): y and every column of W, per row group (joint), as time series over the block's
/// samples. P·τ loses the harmonics of Coulomb's square wave and of the loop's nonlinear
/// response; P·W loses the same, so P·y = P·W·θ stays exact. The block must hold every joint's
/// row of every sample of the projector's window (no zero-velocity removal). Throws dynid::Error
/// otherwise.
EquationBlock project_equations(const EquationBlock& block, const SignalProjector& projector);

/// Intervals of an estimate on projected equations with honest degrees of freedom: the projected
/// residual of each channel lies in a rank-d subspace, so σ² = ‖ẽ_w‖²/(Σ d − rank) (not over the
/// rows) and C = σ²·(W̃_wᵀW̃_w)⁻¹, W̃_w the projected rows weighted as the estimator weighted them
/// (WLS: 1/σ_g per joint from group_variance; OLS, RLS: 1); Student-t intervals with Σ d − rank
/// degrees of freedom. `effective_rows` = Σ over runs and joints of the projector's rank. The
/// correlated-residual warning of the estimate stage is dropped (projected residuals are smooth
/// by construction).
/// `channel` (per row, e.g. run·n + joint; empty = none): model error shows as channels that
/// disagree about a parameter beyond their noise (seed 2's one-joint runs: a held joint's friction
/// in its gravity rows), which the white σ² above, pooled over all channels, does not see. The
/// channel-clustered sandwich C_cl = B·(Σ_c g_c g_cᵀ)·B·G/(G−1)·(N−1)/(N−K) (B = (W̃_wᵀW̃_w)⁻¹,
/// g_c = W̃_cᵀẽ_c, G channels, N = effective_rows, K = rank; Liang–Zeger 1986, CR1) measures that
/// disagreement; with few channels it is unreliable on its own, so each parameter's variance is
/// the larger of the two (Angrist–Pischke 2009 §8.2.3), with the white correlations
/// (C = S·C_white·S, S = diag(max(1, σ_cl/σ_white))): PSD, never narrower than the white one.
/// Parameters widened by more than 20 % are named in a warning. docs/methods/closed_loop.md.
/// When effective_rows ≤ the parameters the estimate still exists but its projected residual
/// measures no noise (issue 25 item 3): `remainder_variance` (per row, the variance of its
/// channel's torque remainder u − P·u, ClosedLoopRun::torque_remainder_std²) then gives the
/// covariance B·(Σ_i σ_i²·w̃_i·w̃_iᵀ)·B (white noise across the band), covariance_kind
/// "torque remainder, projected", with a warning that says so.
/// Returns the one-line covariance choice. Throws dynid::Error when `channel` or
/// `remainder_variance` has the wrong size, or when effective_rows ≤ the parameters without a
/// usable remainder variance.
std::string projected_statistics(Estimate& estimate, const EquationBlock& block,
                                 Eigen::Index effective_rows, bool weighted,
                                 const EstimationOptions& options,
                                 const Eigen::VectorXi& channel = Eigen::VectorXi(),
                                 const Eigen::VectorXd& remainder_variance = Eigen::VectorXd());

/// Refuses what identify() cannot do with options.closed_loop: another model than the
/// differential one, or not one reference per run (none needed without a
/// closed-loop method). Throws dynid::UsageError / dynid::Error naming the fix.
void check_closed_loop_request(const IdentifyOptions& options, size_t runs, size_t references);

/// Seed 2 Table 3's statistic over n repeated identifications (periods or runs).
struct RepeatedEstimate {
  int n = 0;                       ///< estimates
  std::vector<std::string> names;  ///< parameters every estimate has
  Eigen::VectorXd mean, std_dev;   ///< over the n estimates (std with n − 1)
  Eigen::VectorXd ci_half_width;   ///< t_{(1+level)/2}(n − 1)/√(n − 1)·std (Table 3)
  double confidence_level = 0.0;   ///< level of ci_half_width
};

/// Mean, standard deviation and Table 3's half-width t_γ(n−1)/√(n−1)·σ of repeated estimates
/// (seed 2 §3.5, Table 3: n = 30, ratio t₀.₉₉₉₅(29)/√29 = 0.6795). Each estimate is (names,
/// values); only names present in every estimate are reported, in the first one's order.
/// Throws dynid::Error for fewer than 2 estimates or a level outside (0, 1).
RepeatedEstimate repeated_statistics(
    const std::vector<std::pair<std::vector<std::string>, Eigen::VectorXd>>& estimates,
    double confidence_level);

/// What `identify --repeat` identifies on its own.
enum class RepeatOver {
  kPeriods,  ///< each whole period of each run (period: the reference's exact period)
  kRuns      ///< each run
};

/// The pieces `identify --repeat` identifies one by one: each whole period of each run, or each
/// run, with its reference (periods: the reference's derivatives from its Fourier series over the
/// whole run, so that one period can be told periodic).
struct RepeatedPieces {
  std::vector<JointRecord> runs;
  std::vector<ReferenceRecord> references;  ///< one per piece, or empty (no closed-loop method)
};

/// Splits runs into RepeatedPieces with every check that can refuse the request, so that a caller
/// runs it before any estimate (the comau-s2 25-period run spent 368 s on the whole-run estimate
/// before the repeat was refused). A held joint (constant reference; seed 2's one-joint runs) is
/// accepted. references: one per run, or empty (kRuns without a closed-loop method only).
/// Throws dynid::Error for kPeriods without a reference per run, every reference of a run
/// constant, a reference that is not periodic with two periods in its run, fewer than 2 pieces,
/// and a closed-loop method without a reference per run.
RepeatedPieces repeated_pieces(const std::vector<JointRecord>& runs,
                               const std::vector<ReferenceRecord>& references,
                               const IdentifyOptions& options, RepeatOver over);

/// Seed 2 Table 3: identify() on each piece alone, then repeated_statistics() of the estimates at
/// options.confidence_level. Throws as identify() does on a piece.
RepeatedEstimate identify_repeated(const Model& model, const RepeatedPieces& pieces,
                                   const IdentifyOptions& options);

/// repeated_pieces() then identify_repeated() on them. Throws as those do.
RepeatedEstimate identify_repeated(const Model& model, const std::vector<JointRecord>& runs,
                                   const std::vector<ReferenceRecord>& references,
                                   const IdentifyOptions& options, RepeatOver over);

}  // namespace dynid
