#pragma once

namespace dynid {

/// What identify() does with gross torque outliers.
enum class OutlierPolicy {
  kReport,  ///< keep them and warn (sample, joint, value); the default, see docs/cli.md
  kDrop,    ///< replace each by the median of its neighbours and warn
};

/// Gross-outlier test on the logged torques (a Hampel filter with a global scale).
struct OutlierOptions {
  OutlierPolicy policy = OutlierPolicy::kReport;  ///< report or drop what is found
  int half_window = 3;      ///< neighbours on each side for the local median (7-sample window)
  double threshold = 10.0;  ///< flag |tau − local median| above threshold × scale
  /// The scale is max(1.4826·MAD of the local residuals, signal_fraction × 1.4826·MAD of tau_j):
  /// the floor keeps noiseless or quantised logs (MAD = 0) from flagging every curvature peak,
  /// and real ripple from counting as gross (at 0.1 the TX40 run had 15 false alarms in its
  /// bursts of current ripple; at 0.5 its largest residual is 0.21 of the threshold).
  double signal_fraction = 0.5;
};

}  // namespace dynid
