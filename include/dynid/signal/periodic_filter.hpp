#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynid/signal/lowpass_design.hpp"

namespace dynid {

/// Options of lowpass_periodic() (Ceres style).
struct PeriodicLowpassOptions {
  /// The low-pass (sample_rate_hz = the rate of the period's samples); designed with unit DC gain
  /// (design_lowpass_unit_dc), as identify's filter.
  LowpassOptions design;
  /// Keep every N-th sample after filtering (seed 2 §3.4: 1 kHz → 200 Hz is N = 5); N must divide
  /// the samples per period, and the cut-off must lie below the new Nyquist rate.
  int decimate = 1;
};

/// Zero-phase filtering of ONE PERIOD of a periodic signal (each column of x, P samples × c),
/// applied circularly: bin k of each column's DFT is multiplied by |H(e^{j2πk/P})|², H the
/// cascade's response. Identity: the result equals the steady state of filtfilt() applied to the
/// signal repeated forever (no edge transient, no padding, nothing trimmed), so a sine on the
/// period's grid comes out scaled by |H|² at its frequency and not shifted. For an averaged period
/// (dynid average) this is seed 2 §3.4's "8th-order Chebyshev low-pass at 80 Hz" without edges.
/// Throws dynid::Error for fewer than 2 rows or NaN/Inf in x.
Eigen::MatrixXd filtfilt_periodic(const SosFilter& filter,
                                  const Eigen::Ref<const Eigen::MatrixXd>& x);

/// One period filtered with filtfilt_periodic() of design_lowpass_unit_dc(options.design), then
/// every options.decimate-th sample kept (rows 0, N, 2N, …; P/N rows). Throws dynid::Error for
/// N < 1, N not dividing P = x.rows() (the kept samples would not be uniform across the period's
/// wrap; message names P and the divisors to use), fewer than 2 samples left, a cut-off at or
/// above the decimated Nyquist rate sample_rate_hz/(2N) (aliasing), and as design_lowpass().
Eigen::MatrixXd lowpass_periodic(const PeriodicLowpassOptions& options,
                                 const Eigen::Ref<const Eigen::MatrixXd>& x);

/// One period after lowpass_periodic(): its kept rows.
struct LowpassedPeriod {
  Eigen::VectorXd phase;  ///< P/N phase times [s]: the input's rows 0, N, 2N, …
  Eigen::MatrixXd x;      ///< P/N × c: the columns `filtered` low-passed, the others as given
};

/// The mean period x (P × c, phase times `phase`, P) with the columns listed in `filtered`
/// passed through lowpass_periodic(options, ·) and every other column (a noise-free reference,
/// kept with its analytic derivatives) and the phase taken at the same kept rows 0, N, 2N, …, so
/// that every row of the result is one instant (seed 2 §3.4's filtered, resampled average).
/// Throws dynid::Error for a phase that is not P long, a column index outside x, and as
/// lowpass_periodic().
LowpassedPeriod lowpass_period_columns(const PeriodicLowpassOptions& options,
                                       const Eigen::Ref<const Eigen::VectorXd>& phase,
                                       const Eigen::Ref<const Eigen::MatrixXd>& x,
                                       const std::vector<Eigen::Index>& filtered);

}  // namespace dynid
