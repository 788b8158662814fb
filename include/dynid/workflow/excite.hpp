#pragma once

// `dynid excite` without its files (issue 29 item 3): the optimised Fourier excitation with the
// checks and refusals of the command line, and the one-joint experiment references of seed 2,
// checked against the robot's limits. The command line and the Python module call these.

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "dynid/excitation/excitation_optimization.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// An optimised excitation as `dynid excite` writes it.
struct Excitation {
  ExcitationResult result;            ///< optimize_excitation()'s
  TrajectorySamples samples;          ///< one period sampled at the rate, both ends included
  nlohmann::json json;                ///< the --json file (excitation_to_json())
  std::vector<std::string> warnings;  ///< a violated constraint written anyway
};

/// Optimises a finite-Fourier-series excitation (seed 1 §V, seed 2 §3.3; optimize_excitation())
/// and samples one period at `rate` [Hz]. Refused before the search (dynid::UsageError naming the
/// command line's flag): fewer than 2 harmonics with rest at the ends (no free coefficient), f0
/// or rate not > 0, a period too short or too long for the rate. Refused after it (dynid::Error):
/// a trajectory that does not excite every base parameter, and one that violates a constraint
/// unless `allow_violations` (then a warning naming the tightest constraint and the flag that
/// relaxes it).
Excitation excite_fourier(const Model& model, const ExcitationOptions& options, double rate,
                          bool allow_violations);

/// Options of a one-joint experiment reference (`dynid excite --family F --joint J`, seed 2 §3.1
/// and §3.2): one joint moves, the others stay at `pose`.
struct JointReferenceOptions {
  /// fourier (joint_fourier_reference(): Schroeder phases, amplitudes 1/k, scaled to `range`),
  /// slope (constant-velocity slopes, gravity), bang-bang (friction), trapezoid or spline.
  std::string family = "fourier";
  int joint = 0;                                   ///< the joint that moves, 0-based
  std::vector<double> pose;                        ///< the others' positions; empty: 0 or mid-range
  std::optional<std::pair<double, double>> range;  ///< FROM, TO of the joint [rad or m]
  double velocity = 0.0;                           ///< slope, trapezoid: cruise speed [rad/s]
  double acceleration = 0.0;                       ///< slope, bang-bang, trapezoid [rad/s²]
  int cycles = 1;            ///< slope, bang-bang, trapezoid: FROM-TO-FROM cycles
  double dwell = 0.0;        ///< rest between moves [s]
  std::vector<double> via;   ///< spline: positions equally spaced in time, at rest at both ends
  double duration = 0.0;     ///< spline: duration [s]
  int harmonics = 5;         ///< fourier: harmonics
  double f0 = 0.1;           ///< fourier: fundamental [Hz]
  bool rest_at_ends = true;  ///< fourier: zero velocity and acceleration at both ends
  double rate = 100.0;       ///< sample rate [Hz]
  double limit_fraction =
      1.0;  ///< positions in this central fraction of their range, speeds below it
  std::vector<double> dq_max;   ///< |dq| limits [rad/s], 1 or n values; empty: the model's
  std::vector<double> ddq_max;  ///< |ddq| limits [rad/s²], 1 or n values; empty: none
};

/// The samples of a one-joint reference, checked against the model's limits narrowed by
/// limit_fraction (and dq_max, ddq_max). Throws dynid::UsageError naming the command line's flag
/// for an unknown family, a joint out of range, a missing or non-positive parameter, and a
/// sample beyond a limit (with what to change).
TrajectorySamples joint_experiment_reference(const Model& model,
                                             const JointReferenceOptions& options);

/// 1 or n limits as an n-vector (empty: empty). Throws dynid::UsageError naming `flag`.
Eigen::VectorXd joint_limits_of(const std::vector<double>& values, int n, const char* flag);

}  // namespace dynid
