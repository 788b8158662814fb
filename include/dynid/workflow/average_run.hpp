#pragma once

// `dynid average` after its file is read (issue 29 item 3): the mean period of a periodic run,
// optionally low-passed circularly and decimated, and the noise of every channel, as the command
// line writes them. The Python module calls it too.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "dynid/signal/period_averaging.hpp"

namespace dynid {

/// Options of average_run(), the flags of `dynid average`.
struct AverageRunOptions {
  double period = 0.0;  ///< period of the excitation [s], > 0; need not be whole samples
  /// Time of the first period's start [s]; NaN: the first sample.
  double start = std::numeric_limits<double>::quiet_NaN();
  int skip_periods = 0;         ///< complete periods dropped at the start (transient), >= 0
  std::string filter = "none";  ///< none, butterworth[:ORDER] or chebyshev[:ORDER[:RIPPLE_DB]]
  double cutoff_hz = 0.0;       ///< cut-off of `filter` [Hz], > 0 with a filter
  int decimate = 1;             ///< keep every N-th sample of the filtered period, >= 1
};

/// The mean period and the noise statistics of a run, as `dynid average` writes them.
struct AveragedRun {
  std::vector<std::string> columns;  ///< t, then the averaged columns: the --out CSV header
  Eigen::MatrixXd mean;              ///< phase [s] from the period start, then the columns
  /// The --json file without data and out (the file names): period, sample_time, periods,
  /// channels (name, std, std_averaged, skewness, kurtosis, normality_p), filter, warnings, ...
  nlohmann::json json;
  TimedPeriodAverage average;         ///< average_periods_in_time()'s result
  double rate_hz = 0.0;               ///< sample rate of `mean` [Hz]
  std::vector<std::string> warnings;  ///< check_period_repeats(): the period does not repeat
};

/// Throws dynid::UsageError (naming the command line's flag) for an option out of range: a period
/// that is not > 0, negative skip_periods, an unknown or automatic filter, a filter without a
/// cut-off or a cut-off without a filter, decimation below 1 or without a filter.
void check_average_run_options(const AverageRunOptions& options);

/// Averages the complete periods of the columns `x` (m × c, named `names`, sampled at `t`) with
/// average_periods_in_time() (seed 2 §3.4 and Fig. 5), then, with a filter, low-passes the mean
/// period circularly (zero phase, no edge) and decimates it, leaving the reference channels
/// (qr*, dqr*, ddqr*) as logged. The noise statistics are those of the raw samples (std) and of
/// the mean period written (std_averaged). Throws as check_average_run_options(), and
/// dynid::Error as average_periods_in_time() and the filter do.
AveragedRun average_run(const Eigen::VectorXd& t, const Eigen::MatrixXd& x,
                        const std::vector<std::string>& names, const AverageRunOptions& options);

}  // namespace dynid
