#pragma once

#include <vector>

#include <Eigen/Core>

namespace dynid {

/// Options of project_on_reference() (stage 1 of the projection method).
struct ProjectionOptions {
  int m1 = -1;  ///< non-causal lags (future reference samples, seed 2 eq. 10); −1 = choose
  int m2 =
      -1;  ///< causal lags (past reference samples); −1 = choose (m1, m2 both given or both −1)
  /// Largest M1 = M2 tried when choosing, unless a larger one (as long as the run allows) is
  /// needed to keep min_rank dimensions.
  int max_order = 128;
  double significance = 0.01;  ///< family-wise level of the remainder–reference correlation test
  int test_lags = -1;  ///< largest |lag| tested; −1 = max(100, 3·max(M1, M2)), at most m/4
  double rank_tolerance = 1e-10;  ///< eigenvalues of the lagged-reference Gram below this × the
                                  ///< largest are dropped (a few-harmonic reference spans few
                                  ///< dimensions; the projection is still unique)
  /// Dimensions the reference spans (2L + 1 for a periodic reference with L lines, the constant
  /// included; prepare_closed_loop sets it): the automatic order is the smallest that keeps at
  /// least this many as well as passing the test. 0 = no such requirement.
  int min_rank = 0;
};

/// How identify() prepares a closed-loop run (docs/design.md §8, "prepare"; seed 2 §2.2 and §3.4).
enum class ClosedLoopMethod {
  kNone,        ///< the measured signals, filtered and differentiated (direct identification)
  kProjection,  ///< projected on the lagged references (Forssell–Ljung; seed 2 eqs. 10–12)
  kSpectral  ///< a periodic reference's lines up to its band (seed 2 §3.4), derivatives analytic
};

/// Options of the closed-loop preparation (Ceres style).
struct ClosedLoopIdOptions {
  ClosedLoopMethod method = ClosedLoopMethod::kNone;  ///< which preparation
  ProjectionOptions projection;                       ///< FIR orders and their test (projection)
  /// Spectral: a harmonic of f0 whose reference amplitude exceeds this fraction of the largest
  /// harmonic of the same joint is a line of the excitation; the band ends at the highest line.
  double line_fraction = 1e-3;
  /// Spectral: the reference's period [s] as the user knows it (`--period`, `--f0`); 0 = detected
  /// from qr, which must then repeat exactly. A given period must be a whole number of samples
  /// (to 1e-6 of one) with two periods in the run, and qr must repeat with it to
  /// `given_period_tolerance` of its range.
  double period = 0.0;
  /// Spectral with a given period: largest |qr(t + T) − qr(t)| accepted, as a fraction of each
  /// joint's range (a logged reference is rounded; a larger mismatch means the period is wrong).
  double given_period_tolerance = 1e-3;
  /// The torque logged at t acts at t + offset [s] (SignalOptions::torque_time_offset; identify()
  /// copies it): re-interpolated before the projection.
  double torque_time_offset = 0.0;
};

/// The reference a closed-loop run followed, sample for sample with the run (docs/design.md §4:
/// qr*).
struct ReferenceRecord {
  Eigen::MatrixXd qr;    ///< m × n [rad or m]
  Eigen::MatrixXd dqr;   ///< m × n or empty: derived from qr (spectrally when it is periodic)
  Eigen::MatrixXd ddqr;  ///< m × n or empty: derived like dqr
};

/// Raw sensor noise of a run for the maximum-likelihood estimator (seed 2 eq. 16's σ), per joint,
/// as `dynid average` measures it: std of the logged q [rad or m] and τ [N·m or N] (before any
/// filter; identify() carries them through its filter and differentiation). Empty = estimated
/// from the data (the white floor of each signal's spectrum).
struct SensorNoise {
  Eigen::VectorXd q;    ///< n entries ≥ 0, or empty
  Eigen::VectorXd tau;  ///< n entries > 0, or empty
};

/// The lines of a periodic excitation as the spectral preparation found them (seed 2 §3.4).
struct ExcitationSpectrum {
  double f0_hz = 0.0;      ///< fundamental [Hz] = 1/(period_samples·Ts)
  int period_samples = 0;  ///< samples per reference period (detected, exact)
  int periods = 0;         ///< whole periods used (the last ones of the run)
  int band_harmonic = 0;   ///< H: harmonics 1…H of f0 kept (the highest line)
  std::vector<int> lines;  ///< harmonics of f0 that carry reference energy (line_fraction)
  /// Per joint, fraction of the reference's (mean-removed) energy above the band (≈ 0).
  Eigen::VectorXd reference_energy_above_band;
  /// Per joint, fraction of the torque's (mean-removed) energy the preparation removes: noise,
  /// and the loop's response outside the kept lines.
  Eigen::VectorXd torque_energy_removed;
};

/// What the closed-loop preparation of one run chose and found (reported in the result JSON).
struct ClosedLoopReport {
  ClosedLoopMethod method = ClosedLoopMethod::kNone;
  int rank = 0;                  ///< dimensions per projected channel (interval dof per joint)
  int m1 = 0, m2 = 0;            ///< projection: FIR orders used
  Eigen::VectorXd correlation;   ///< projection: per joint corr(û, ũ) (seed 2 reports 2.9e-14)
  double max_z = 0.0;            ///< projection: remainder–reference test statistic
  double threshold = 0.0;        ///< projection: its Bonferroni bound
  bool test_passed = false;      ///< projection: max_z ≤ threshold
  ExcitationSpectrum spectrum;   ///< spectral: the lines kept
  int reference_dimensions = 0;  ///< projection: 2L + 1 for a periodic reference, else 0
  std::vector<int> held_joints;  ///< joints (0-based) whose reference is constant, taken as still
};

}  // namespace dynid
