#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "dynid/closed_loop/closed_loop_options.hpp"
#include "dynid/identification/record.hpp"

namespace dynid {

/// Orthogonal projection of signals sampled on a run's window onto a fixed subspace of time
/// series (the span of the lagged references, or the lines of a periodic excitation): the same
/// operator P applied to the torques, positions and every regressor column, so that P·y = P·W·θ
/// keeps the regression exact (Gautier's parallel filtering, with P for the filter).
class SignalProjector {
 public:
  virtual ~SignalProjector() = default;
  /// P·x for x (samples() × k, one signal per column, the window's samples); same size out.
  virtual Eigen::MatrixXd project(const Eigen::Ref<const Eigen::MatrixXd>& x) const = 0;
  /// Dimension of the subspace (per signal): the degrees of freedom one projected signal keeps.
  virtual int rank() const = 0;
  /// Samples of the window the projector acts on.
  virtual Eigen::Index samples() const = 0;
};

/// The remainder–reference correlation test of one FIR order.
struct ProjectionTest {
  int m1 = 0, m2 = 0;
  double max_z = 0.0;      ///< max over torques j, references i, lags |τ| ≤ test_lags of |z|
  double threshold = 0.0;  ///< Bonferroni bound z_{1 − α/(2·count)}
  bool passed = false;     ///< max_z ≤ threshold
};

/// Stage 1 of the projection method: a run projected onto the reference's lagged span.
struct ProjectionResult {
  ProcessedRecord processed;  ///< samples M2 … m−1−M1: q = q̂, dq, ddq through the FIR from the
                              ///< reference's derivatives, tau = û; position_noise_std = std of
                              ///< the position remainder q − q̂ per joint
  int m1 = 0, m2 = 0;           ///< FIR orders used
  Eigen::VectorXd correlation;  ///< per joint corr(û_j, ũ_j) (0 up to rounding by construction)
  Eigen::VectorXd torque_remainder_std;  ///< per joint std of ũ = u − û [N·m or N]
  /// (n·(M1 + M2 + 1) + 1) × 2n FIR coefficients: row i·(M1 + M2 + 1) + (k + M1) is s_k of
  /// reference i (zero for a held one), the last row the constant; columns torques 1..n then
  /// positions 1..n.
  Eigen::MatrixXd fir;
  std::vector<ProjectionTest> tests;  ///< every order tried (the chosen one last)
  /// Joints (0-based) whose reference is constant (held by their controller): left out of the
  /// FIR's inputs, their projected dq, ddq set to zero.
  std::vector<int> held_joints;
  /// A chosen or given order whose remainder fails the test, or an automatic order that cannot
  /// keep options.min_rank dimensions in the run's length: what it means and the fix.
  std::vector<std::string> warnings;
  /// The projection onto the lagged-reference span on the window's samples (rank: the Gram's
  /// numerical rank, 2H + 1 for references that share H harmonics whatever the run length).
  std::shared_ptr<const SignalProjector> projector;
};

/// Estimates the non-causal multi-input FIR u_j(t) = Σ_i Σ_{k=−M1}^{M2} s_{jik}·r_i(t − k) + c_j
/// from the references r = qr (m × n) to the torques (seed 2 eqs. 10–11, Forssell–Ljung 2000) and
/// the same for the positions, by least squares over t = M2 … m−1−M1, and returns the projected
/// signals: û, q̂, and q̂'s derivatives as the same FIR applied to dqr, ddqr (no measured signal
/// is differentiated). A constant reference column (a joint held while others move, seed 2
/// section 3's one-joint runs) is in the span of the constant c_j: the FIR's inputs are the moving
/// references, and the held joints' q̂', q̂'' are zero (their motion is tracking error).
/// Unless given, M1 = M2 = M is the smallest M of 2, 4, 8, 12, 16, 24, 32,
/// 48, 64, 96, 128, … ≤ max_order (larger while min_rank is not reached and the run allows)
/// whose projector keeps options.min_rank dimensions and whose
/// torque remainder ũ passes the cross-correlation test
/// of Ljung, "System Identification" (1999) §16.6: for every torque j, reference i and lag
/// |τ| ≤ test_lags (inside and outside the window), z = √N·ρ̂_{ũr}(τ)/√P with
/// P = Σ_{|k|≤L} ρ̂_ũ(k)·ρ̂_r(k) (Bartlett's variance of the cross-correlation of two independent
/// series), and max |z| ≤ the Bonferroni bound at `significance`; when none passes, the largest
/// is used; a failed test (given or chosen order) and a rank short of min_rank are warnings.
/// t is uniform [s], all matrices m × n, n = run.q.cols().
/// Throws dynid::Error for no reference columns, sizes that do not match, NaN/Inf, every
/// reference column constant (nothing moves), only one of m1/m2 given or negative, or FIR
/// orders whose window M1 + M2 + 1 plus the regressors leave fewer rows than 4 × the columns.
ProjectionResult project_on_reference(const JointRecord& run,
                                      const Eigen::Ref<const Eigen::MatrixXd>& qr,
                                      const Eigen::Ref<const Eigen::MatrixXd>& dqr,
                                      const Eigen::Ref<const Eigen::MatrixXd>& ddqr,
                                      const ProjectionOptions& options = {});

}  // namespace dynid
