#pragma once

// Preparation steps that identify() and validate_torques() share, so that a validation compares
// the same kind of rows as the fit (implemented in record.cpp).

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/identification/record.hpp"
#include "dynid/model/model.hpp"
#include "dynid/regressor/parameter_layout.hpp"

namespace dynid {

/// preprocess() of a run of `model`, after checking that it has one column per joint. Throws
/// dynid::Error naming both joint counts otherwise.
ProcessedRecord preprocess_run(const Model& model, const JointRecord& record,
                               const SignalOptions& options,
                               std::vector<std::pair<std::string, std::string>>& choices);

/// Throws dynid::UsageError for a cut-off that is NaN, infinite or negative, a negative decimation
/// or a trim below −1: values the automatic rules would otherwise silently replace.
void check_signal_options(const SignalOptions& options);

/// Throws dynid::Error for the first sample of r.q, r.dq, r.ddq or r.tau that find_corrupt_sample()
/// (signal/plausibility.hpp) flags, naming column, sample, time and value, then `fix`. preprocess()
/// calls it, so every path that prepares a run (differential, integral, gravity, friction,
/// decoupled, payload, validate) refuses the sample before it turns the estimate into NaN.
void check_corrupt_samples(const JointRecord& r, const std::string& fix);

/// Per joint, the |dq_j| [rad/s or m/s] below which rows are left out of a Coulomb model's fit:
/// the given signal.zero_velocity (1 or n values), or max(zero_velocity_fraction × max|dq_j|,
/// zero_velocity_noise_multiple × the processed velocity's noise std). Zeros without Coulomb
/// friction in `layout`. The choice, described with `verb` ("removed"), goes to `choices`.
/// Throws dynid::UsageError for a count that is neither 1 nor n, or a rule parameter out of range.
Eigen::VectorXd zero_velocity_threshold(const ParameterLayout& layout, const SignalOptions& signal,
                                        const ProcessedRecord& processed, const char* verb,
                                        std::vector<std::pair<std::string, std::string>>& choices);

/// Sets the velocity, acceleration and Coulomb indicators of every joint whose processed velocity
/// never leaves 6 × its noise std (or whose position is constant) to zero: a joint the controller
/// held still, whose jitter must not excite velocity-driven columns. Names them in `choices`.
void hold_still_joints(const Model& model, ProcessedRecord& processed,
                       std::vector<std::pair<std::string, std::string>>& choices);

}  // namespace dynid
