// `dynid average`: mean period and per channel noise statistics of a periodic run.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/signal/period_averaging.hpp"

namespace dynid::cli {
namespace {

struct AverageCliOptions {
  std::string data, out, json;
  double period = 0.0, f0 = 0.0, start = std::nan("");
  int skip_periods = 0;
};

void run(const AverageCliOptions& o) {
  if ((o.period > 0.0) == (o.f0 > 0.0))
    throw UsageError("give exactly one of --period S or --f0 HZ (> 0)");
  if (o.skip_periods < 0) throw UsageError("--skip-periods must be >= 0");
  const double period = o.period > 0.0 ? o.period : 1.0 / o.f0;
  const CsvTable table = read_csv(o.data);
  Eigen::Index t_col = -1;
  std::vector<std::string> names;
  std::vector<Eigen::Index> cols;
  for (Eigen::Index c = 0; c < static_cast<Eigen::Index>(table.columns.size()); ++c) {
    if (table.columns[c] == "t") {
      t_col = c;
    } else {
      names.push_back(table.columns[c]);
      cols.push_back(c);
    }
  }
  if (t_col < 0) throw Error(o.data + " has no t column: period averaging needs the sample times");
  if (cols.empty()) throw Error(o.data + " has no column besides t: nothing to average");
  Eigen::MatrixXd x(table.data.rows(), static_cast<Eigen::Index>(cols.size()));
  for (Eigen::Index j = 0; j < x.cols(); ++j) x.col(j) = table.data.col(cols[j]);
  TimedPeriodAverageOptions options;
  options.start = o.start;
  options.skip_periods = o.skip_periods;
  const TimedPeriodAverage a = average_periods_in_time(table.data.col(t_col), x, period, options);

  std::vector<std::string> header = {"t"};
  header.insert(header.end(), names.begin(), names.end());
  Eigen::MatrixXd mean(a.mean.rows(), a.mean.cols() + 1);
  mean << a.phase, a.mean;
  nlohmann::json j;
  if (!o.json.empty()) {
    j["data"] = o.data;
    j["period"] = period;
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
    j["channels"] = nlohmann::json::array();
    for (std::size_t c = 0; c < names.size(); ++c) {
      const ChannelNoise& ch = a.channels[c];
      j["channels"].push_back({{"name", names[c]},
                               {"std", ch.std},
                               {"skewness", json_number(ch.skewness)},
                               {"kurtosis", json_number(ch.kurtosis)},
                               {"normality_p", json_number(ch.normality_p)}});
    }
  }
  write_csv(o.out, header, mean);
  if (!o.json.empty()) write_json(o.json, j);
  std::cout << "averaged " << a.periods << " periods of " << short_number(period) << " s ("
            << short_number(a.samples_per_period) << " samples"
            << (a.interpolated ? ", interpolated between samples" : "") << "); wrote " << o.out
            << (o.json.empty() ? "" : " and " + o.json) << '\n';
  if (a.samples_after > 0)
    std::cout << "note: the last " << a.samples_after << " samples ("
              << short_number(a.partial_period)
              << " of a period) are an incomplete period, not used\n";
  if (a.samples_before > 0)
    std::cout << "note: the first " << a.samples_before
              << " samples are before the first averaged period, not used\n";
}

}  // namespace

void add_average_command(CLI::App& app) {
  auto o = std::make_shared<AverageCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "average",
      "Mean period of a periodic run and the noise of every channel (std, skewness, kurtosis, "
      "normality test), as in B. Bona, A. Curatella, Closed-loop rigid model identification of "
      "an industrial robot, 2005");
  cmd->add_option("--data,-d", o->data, "Run CSV with t and any other columns (q*, tau*, ...)")
      ->required();
  cmd->add_option("--period", o->period,
                  "Period of the excitation [s]; need not be a whole number of samples");
  cmd->add_option("--f0", o->f0, "Fundamental frequency [Hz] instead of --period (period 1/f0)");
  cmd->add_option("--out,-o", o->out,
                  "Mean period CSV: t (phase from the period start) and the "
                  "same columns")
      ->required();
  cmd->add_option("--json", o->json,
                  "Noise JSON: periods, samples_per_period, partial_period, channels (name, std, "
                  "skewness, kurtosis, normality_p)");
  cmd->add_option("--start", o->start,
                  "Time of the first period's start [s]; default the first sample");
  cmd->add_option("--skip-periods", o->skip_periods,
                  "Complete periods dropped at the start (transient)")
      ->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace dynid::cli
