#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// Limits of check_run_plausibility(); defaults for an arm logged in SI units.
struct PlausibilityOptions {
  double min_rate_hz = 1.0;    ///< below: time stamps are not in seconds (ms, µs) — error
  double max_rate_hz = 100e3;  ///< above: time stamps are not in seconds (e.g. minutes) — error
  double low_rate_hz = 20.0;   ///< below (but ≥ min): accelerations are unreliable — warning
  double still_range = 1e-4;   ///< a joint whose position range is below this does not move
  /// A torque column exactly 0 in more than this fraction of the samples was not logged (or only
  /// part of the time): a measured torque, current × constant with noise, is exactly 0 only
  /// inside half a quantisation step around zero — warning.
  double unlogged_zero_fraction = 0.5;
};

/// The time-units diagnosis of a run (identify through check_run_plausibility(), validate
/// through validate_torques(), so that both name the same cause): throws dynid::Error when the
/// sample rate (m−1)/(t_end − t_0) lies outside [min_rate_hz, max_rate_hz] (time stamps in ms or
/// µs, or a --rate not in Hz); returns a warning when it is below low_rate_hz.
std::optional<std::string> check_sample_rate(const Eigen::Ref<const Eigen::VectorXd>& t,
                                             const PlausibilityOptions& options = {});

/// Checks that a run looks like a robot run in SI units before anything is estimated from it:
/// the sample rate passes check_sample_rate() (else the time stamps are in ms or µs and every
/// parameter would come out 10⁶× off), some torque is non-zero, some
/// joint moves. t: m strictly increasing time stamps [s]; q, tau: m × n [rad or m, N·m or N];
/// `joints`: n names for the messages. Throws dynid::Error naming the fault and the fix for the
/// run as a whole; returns named warnings (one line each) for single joints: torque zero in every
/// sample, torque exactly zero in more than unlogged_zero_fraction of the samples, position range
/// below still_range, and a rate below low_rate_hz.
std::vector<std::string> check_run_plausibility(const Eigen::Ref<const Eigen::VectorXd>& t,
                                                const Eigen::Ref<const Eigen::MatrixXd>& q,
                                                const Eigen::Ref<const Eigen::MatrixXd>& tau,
                                                const std::vector<std::string>& joints,
                                                const PlausibilityOptions& options = {});

/// One sample of a column that no robot run holds (find_corrupt_sample()).
struct CorruptSample {
  Eigen::Index sample = 0;  ///< row (0-based)
  Eigen::Index column = 0;  ///< column (0-based)
  double value = 0.0;       ///< the sample
  double median = 0.0;      ///< median of its column
  double limit = 0.0;       ///< the largest distance from the median a sample may have
};

/// Distance from its column's median, in units of max(1.4826·MAD of the column, `floor`), beyond
/// which a sample is corrupt: a run's samples spread over a few MADs; one 1e4 MADs away is a
/// logging fault, and its square (1e200 N·m, 1e155 rad through two derivatives) overflows the
/// normal equations into an all-NaN fit.
constexpr double kCorruptSpreads = 1e4;

/// The first sample (by row, then column) of x (m × n) further than kCorruptSpreads ×
/// max(1.4826·MAD_j, floor) from the median of its column j, or none. `floor` [the column's unit]
/// keeps a column that is mostly constant (MAD 0) from flagging its few real moves. No throw.
std::optional<CorruptSample> find_corrupt_sample(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                                 double floor);

/// Magnitudes no sample of a run in SI units reaches, for the paths that cannot see a whole
/// column (identify --stream reads each row once): beyond them a sample is corrupt, and its
/// square overflows the accumulated normal equations.
constexpr double kMaxPlausiblePosition = 1e6;      ///< |q| [rad or m]: 1.6e5 turns
constexpr double kMaxPlausibleVelocity = 1e6;      ///< |dq| [rad/s or m/s]
constexpr double kMaxPlausibleAcceleration = 1e9;  ///< |ddq| [rad/s² or m/s²]
constexpr double kMaxPlausibleTorque = 1e9;        ///< |tau| [N·m or N]

}  // namespace dynid
