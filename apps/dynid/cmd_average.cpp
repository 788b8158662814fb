// `dynid average`: mean period and per channel noise statistics of a periodic run.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/option_text.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/signal/period_averaging.hpp"
#include "dynid/signal/periodic_filter.hpp"
#include "dynid/workflow/average_run.hpp"
#include "run_flags.hpp"

namespace dynid::cli {
namespace {

struct AverageCliOptions {
  std::string data, out, json;
  double period = 0.0, f0 = 0.0, start = std::nan("");
  int skip_periods = 0;
  std::string filter = "none";  // --filter
  double cutoff = 0.0;          // --cutoff [Hz]
  int decimate = 1;             // --decimate
  RunFlags run;                 // --rate, --columns, --torque-scale, --rows, --time, ...
};

void run(const AverageCliOptions& o, const CLI::App& cmd) {
  if ((o.period > 0.0) == (o.f0 > 0.0))
    throw UsageError("give exactly one of --period S or --f0 HZ (> 0)");
  AverageRunOptions options;
  options.period = o.period > 0.0 ? o.period : 1.0 / o.f0;
  options.start = o.start;
  options.skip_periods = o.skip_periods;
  options.filter = o.filter;
  options.cutoff_hz = o.cutoff;
  options.decimate = o.decimate;
  check_average_run_options(options);  // before the file is read
  const double period = options.period;
  const bool filtered = o.filter != "none";
  if (run_flag_given(cmd, "--time-shift")) {
    std::cerr << "warning: --time-shift has no effect on dynid average (the columns are averaged "
                 "as logged); give it to identify, which reads the averaged period\n";
  }
  RunFileReport read;
  const RunFileOptions file = run_file_options(o.run);
  RunTable run = read_run_table(o.data, file, read);
  scale_torque_columns(run, file, read);
  for (const auto& w : read.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  // The first note says the file was read; the others what a run flag did to it.
  for (std::size_t i = 1; i < read.notes.size(); ++i)
    std::cerr << "average: " << one_line(read.notes[i]) << '\n';
  const CsvTable& table = run.table;
  std::vector<std::string> names;
  std::vector<Eigen::Index> cols;
  for (Eigen::Index c = 0; c < static_cast<Eigen::Index>(table.columns.size()); ++c) {
    if (table.columns[c] != "t") {
      names.push_back(table.columns[c]);
      cols.push_back(c);
    }
  }
  if (cols.empty()) throw Error(o.data + " has no column besides t: nothing to average");
  Eigen::MatrixXd x(table.data.rows(), static_cast<Eigen::Index>(cols.size()));
  for (Eigen::Index j = 0; j < x.cols(); ++j) x.col(j) = table.data.col(cols[j]);
  const AveragedRun averaged = average_run(run.t, x, names, options);
  const TimedPeriodAverage& a = averaged.average;
  const std::vector<std::string>& warnings = averaged.warnings;
  nlohmann::json j = averaged.json;
  j["data"] = o.data;
  j["out"] = o.out;
  for (const std::string& w : warnings) std::cerr << "warning: " << w << '\n';
  write_csv(o.out, averaged.columns, averaged.mean);
  if (!o.json.empty()) write_json(o.json, j);
  std::cout << "averaged " << a.periods << " periods of " << short_number(period) << " s ("
            << short_number(a.samples_per_period) << " samples"
            << (a.interpolated ? ", interpolated between samples" : "") << "); wrote " << o.out
            << (o.json.empty() ? "" : " and " + o.json) << '\n';
  if (filtered)
    std::cout << "filtered the mean period circularly (" << o.filter << ", zero phase, cut-off "
              << short_number(o.cutoff) << " Hz)"
              << (o.decimate > 1 ? ", kept every " + std::to_string(o.decimate) + "th sample (" +
                                       short_number(averaged.rate_hz) + " Hz, " +
                                       std::to_string(averaged.mean.rows()) + " rows)"
                                 : std::string())
              << "; reference columns (qr*, dqr*, ddqr*) left as logged\n";
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
                  "Noise JSON: periods, samples_per_period, partial_period, channels (name, std of "
                  "the raw samples, std_averaged of the --out mean period, skewness, kurtosis, "
                  "normality_p)");
  cmd->add_option("--start", o->start,
                  "Time of the first period's start [s]; default the first sample");
  cmd->add_option("--skip-periods", o->skip_periods,
                  "Complete periods dropped at the start (transient)")
      ->capture_default_str();
  cmd->add_option("--filter", o->filter,
                  "Zero-phase low-pass of the mean period, applied circularly (no edges): none, "
                  "butterworth[:ORDER] or chebyshev[:ORDER[:RIPPLE_DB]] (order 8 as in Bona and "
                  "Curatella); reference columns qr*, dqr*, ddqr* are not filtered")
      ->capture_default_str();
  cmd->add_option("--cutoff", o->cutoff, "Cut-off of --filter [Hz] (Chebyshev: passband edge)");
  cmd->add_option("--decimate", o->decimate,
                  "Keep every N-th sample of the filtered period (must divide its samples; the "
                  "cut-off must be below the new Nyquist rate), e.g. 5 for 1 kHz to 200 Hz")
      ->capture_default_str();
  add_run_flags(cmd, o->run);
  cmd->callback([o, cmd] { run(*o, *cmd); });
}

}  // namespace dynid::cli
