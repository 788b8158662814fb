#pragma once

#include <string>

#include <Eigen/Core>

#include "dynid/signal/lowpass_design.hpp"

namespace dynid {

/// Options of position_noise_floor() (Ceres style).
struct NoiseFloorOptions {
  /// A frequency band carries motion to identify when its position power is at least this many
  /// times the noise floor (20 dB: amplitude 10× the noise, so that differentiating it to q̈
  /// leaves an errors-in-variables attenuation below 1 %).
  double signal_to_noise = 100.0;
  /// Longest Welch segment [samples] (power of two); shorter records use the largest power of two
  /// that fits.
  int max_segment = 65536;
};

/// White measurement noise and signal bandwidth of uniformly sampled positions, per column.
struct NoiseFloor {
  Eigen::VectorXd noise_std;  ///< σ_q of the white noise floor [rad or m]; NaN if too short
  /// Upper end of the motion's band [Hz]: scanning one-third-octave bands upward from the lowest,
  /// the centre of the last band with signal_to_noise times the floor before a full octave of
  /// bands below it (isolated peaks beyond are ignored); at most rate/4; NaN if too short.
  Eigen::VectorXd signal_edge_hz;
};

/// Welch spectrum of the first difference of each column of q (Blackman–Harris window, 50 %
/// overlap),
/// divided by |1 − e^{−iω}|² so that a white noise of variance σ² gives the flat level σ²: the
/// floor σ_q² is the median one-third-octave band level above rate/4, and the signal edge the
/// highest band below rate/4 that stands signal_to_noise above it. Differencing first keeps the
/// window's leakage from a large slow motion below the floor. q is m × n at rate_hz; records
/// with fewer than 129 samples give NaN. Throws dynid::Error for a rate that is not > 0.
/// Derivation: docs/methods/signal.md ("Noise floor and spectral cut-off rule").
NoiseFloor position_noise_floor(const Eigen::Ref<const Eigen::MatrixXd>& q, double rate_hz,
                                const NoiseFloorOptions& options = {});

/// Bounds and margin of choose_cutoff() (Ceres style).
struct CutoffRule {
  double min_hz = 1.0;                ///< never below (robot dynamics are not slower than this)
  double max_hz = 20.0;               ///< never above (arm rigid-body dynamics live below ~10 Hz)
  double max_fraction_of_rate = 0.1;  ///< and never above this fraction of the sample rate
  /// The cut-off is this multiple of the highest signal edge over the joints: the filter
  /// (Butterworth order 4 applied forward and backward) passes 0.67·cut-off with 4 % loss and
  /// the motion's main harmonics below it with less than 1 %.
  double margin = 1.5;
  NoiseFloorOptions noise;  ///< how the signal edge is found
};

/// A cut-off frequency chosen from the data, with the reason (for `choices`).
struct CutoffChoice {
  double cutoff_hz = 0.0;  ///< chosen low-pass cut-off [Hz]
  std::string reason;      ///< one line: edge, noise, bounds
  NoiseFloor floor;        ///< the per-joint noise floor it is based on
};

/// Low-pass cut-off for parallel filtering of q and tau: margin × the highest per-joint signal
/// edge of position_noise_floor(q), clamped to [min_hz, min(max_hz, max_fraction_of_rate·rate)]
/// (the upper bound when the noise floor is not visible or the record too short).
/// Throws dynid::Error for a rate that is not > 0.
CutoffChoice choose_cutoff(const Eigen::Ref<const Eigen::MatrixXd>& q, double rate_hz,
                           const CutoffRule& rule = {});

/// Noise gain of a processing chain for white noise: σ_out / σ_in for the zero-phase filter
/// (filtfilt; none when `filter` is null) followed by `derivative` (0, 1 or 2) passes of central
/// differences at rate_hz, i.e. sqrt(Σ_k h_k²) for h the impulse response of the chain (computed
/// numerically; units 1/s per derivative). Throws dynid::Error for a rate that is not > 0 or
/// derivative ∉ {0, 1, 2}.
double white_noise_gain(const SosFilter* filter, int derivative, double rate_hz);

}  // namespace dynid
