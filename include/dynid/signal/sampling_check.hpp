#pragma once

#include <Eigen/Core>

namespace dynid {

/// What check_sampling found about a time vector.
struct SamplingInfo {
  double mean_period = 0.0;             ///< (t_last − t_first)/(m − 1) [s]
  double max_relative_deviation = 0.0;  ///< max_k |Δt_k − mean|/mean over the m − 1 steps
  bool uniform = false;                 ///< max_relative_deviation ≤ the tolerance given
  double rate_hz() const { return 1.0 / mean_period; }  ///< mean sample rate [Hz]
};

/// Checks that t (size m ≥ 2, seconds) is finite and strictly increasing and measures how uniform
/// it is. uniform is true when every step is within `relative_tolerance` of the mean period.
/// Throws dynid::Error for fewer than 2 samples, NaN/Inf (naming the first bad sample) or a step
/// t[k] ≤ t[k−1] (naming the first such k, 0-based, and both values).
SamplingInfo check_sampling(const Eigen::Ref<const Eigen::VectorXd>& t,
                            double relative_tolerance = 1e-3);

/// check_sampling, then throws dynid::Error if the sampling is not uniform within the tolerance
/// (for `what`, e.g. "decimation", which needs uniform samples; the message says to resample).
SamplingInfo require_uniform_sampling(const Eigen::Ref<const Eigen::VectorXd>& t,
                                      double relative_tolerance, const char* what);

/// Checks that x (m × n) has one row per time stamp of t (size m); `what` names the caller.
/// Throws dynid::Error otherwise.
void check_time_rows(const char* what, const Eigen::Ref<const Eigen::VectorXd>& t,
                     const Eigen::Ref<const Eigen::MatrixXd>& x);

}  // namespace dynid
