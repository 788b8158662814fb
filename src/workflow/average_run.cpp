#include "dynid/workflow/average_run.hpp"

#include <utility>

#include "dynid/common/error.hpp"
#include "dynid/identification/option_text.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/signal/periodic_filter.hpp"

namespace dynid {

void check_average_run_options(const AverageRunOptions& o) {
  if (!(o.period > 0.0)) throw UsageError("give the period: --period S or --f0 HZ (> 0)");
  if (o.skip_periods < 0) throw UsageError("--skip-periods must be >= 0");
  const bool filtered = o.filter != "none";
  SignalOptions filter;
  apply_filter_text(o.filter, filter);
  if (o.filter == "auto")
    throw UsageError(
        "--filter auto chooses identify's cut-off from a run; for the averaged period name the "
        "filter (butterworth[:ORDER] or chebyshev[:ORDER[:RIPPLE_DB]]) and give --cutoff HZ");
  if (filtered && !(o.cutoff_hz > 0.0))
    throw UsageError("--filter " + o.filter + " needs --cutoff HZ (> 0), e.g. --cutoff 80");
  if (!filtered && o.cutoff_hz != 0.0)
    throw UsageError("--cutoff sets the low-pass of --filter: give --filter too, e.g. chebyshev:8");
  if (o.decimate < 1) throw UsageError("--decimate must be >= 1");
  if (!filtered && o.decimate > 1)
    throw UsageError("--decimate " + std::to_string(o.decimate) +
                     " needs a low-pass against aliasing: give --filter and --cutoff too");
}

AveragedRun average_run(const Eigen::VectorXd& t, const Eigen::MatrixXd& x,
                        const std::vector<std::string>& names, const AverageRunOptions& o) {
  check_average_run_options(o);
  if (static_cast<Eigen::Index>(names.size()) != x.cols())
    throw Error("average: " + std::to_string(x.cols()) + " columns but " +
                std::to_string(names.size()) + " names");
  if (names.empty()) throw Error("the run has no column besides t: nothing to average");
  SignalOptions filter;
  apply_filter_text(o.filter, filter);
  const bool filtered = o.filter != "none";
  AveragedRun out;
  TimedPeriodAverageOptions options;
  options.start = o.start;
  options.skip_periods = o.skip_periods;
  out.average = average_periods_in_time(t, x, o.period, options);
  const TimedPeriodAverage& a = out.average;
  out.warnings = check_period_repeats(a, x, names);

  // Seed 2 section 3.4: averaged, then low-passed (8th-order Chebyshev at 80 Hz) and resampled
  // (200 Hz). The mean is one period of a periodic signal, so the zero-phase filter is circular:
  // no edge transient, nothing trimmed. Averaging and filtering are both linear, so their order
  // does not matter. The noise statistics are those of the raw samples (std) and of the mean
  // period written (std_averaged, what identify --estimator ml needs when it fits the mean).
  PeriodicLowpassOptions lowpass;
  lowpass.design.family = filter.family;
  lowpass.design.order = filter.order;
  lowpass.design.ripple_db = filter.ripple_db;
  lowpass.design.cutoff_hz = o.cutoff_hz;
  lowpass.design.sample_rate_hz = 1.0 / (o.period / static_cast<double>(a.mean.rows()));
  lowpass.decimate = o.decimate;
  std::vector<Eigen::Index> measured;  // columns filtered (every one but the reference's)
  for (Eigen::Index c = 0; c < a.mean.cols(); ++c)
    if (!is_reference_channel(names[static_cast<size_t>(c)])) measured.push_back(c);
  Eigen::MatrixXd kept = a.mean;
  Eigen::VectorXd phase = a.phase;
  if (filtered) {
    LowpassedPeriod f = lowpass_period_columns(lowpass, a.phase, a.mean, measured);
    kept = std::move(f.x);
    phase = std::move(f.phase);
  }
  out.rate_hz = lowpass.design.sample_rate_hz / o.decimate;
  out.columns = {"t"};
  out.columns.insert(out.columns.end(), names.begin(), names.end());
  out.mean.resize(kept.rows(), kept.cols() + 1);
  out.mean << phase, kept;

  nlohmann::json& j = out.json;
  j["period"] = o.period;
  j["sample_time"] = a.sample_time;
  j["samples_per_period"] = a.samples_per_period;
  j["interpolated"] = a.interpolated;
  j["start"] = a.start;
  j["periods"] = a.periods;
  j["skipped_periods"] = o.skip_periods;
  j["samples_before"] = a.samples_before;
  j["samples_after"] = a.samples_after;
  j["partial_period"] = a.partial_period;
  j["residual_samples"] = a.residual_samples;
  j["warnings"] = out.warnings;
  if (filtered) {
    nlohmann::json unfiltered = nlohmann::json::array();
    for (const std::string& name : names)
      if (is_reference_channel(name)) unfiltered.push_back(name);
    j["filter"] = {
        {"family", filter.family == LowpassFamily::kChebyshev1 ? "chebyshev" : "butterworth"},
        {"order", filter.order},
        {"ripple_db", filter.family == LowpassFamily::kChebyshev1 ? json_number(filter.ripple_db)
                                                                  : nlohmann::json()},
        {"cutoff_hz", o.cutoff_hz},
        {"decimate", o.decimate},
        {"rate_hz", out.rate_hz},
        {"rows", kept.rows()},
        {"unfiltered", unfiltered}};
  }
  j["channels"] = nlohmann::json::array();
  for (std::size_t c = 0; c < names.size(); ++c) {
    const ChannelNoise& ch = a.channels[c];
    j["channels"].push_back(
        {{"name", names[c]},
         {"std", ch.std},
         {"std_averaged", averaged_noise_std(ch.std, a.periods, filtered ? &lowpass : nullptr)},
         {"skewness", json_number(ch.skewness)},
         {"kurtosis", json_number(ch.kurtosis)},
         {"normality_p", json_number(ch.normality_p)}});
  }
  return out;
}

}  // namespace dynid
