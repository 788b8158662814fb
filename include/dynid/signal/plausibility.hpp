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
/// sample, position range below still_range, and a rate below low_rate_hz.
std::vector<std::string> check_run_plausibility(const Eigen::Ref<const Eigen::VectorXd>& t,
                                                const Eigen::Ref<const Eigen::MatrixXd>& q,
                                                const Eigen::Ref<const Eigen::MatrixXd>& tau,
                                                const std::vector<std::string>& joints,
                                                const PlausibilityOptions& options = {});

}  // namespace dynid
