#pragma once

// The flags that say how to read a run (issue 26 item 2): one definition and one help text for
// every command that reads one (identify, validate, payload, average), so that a log read by one
// command is read the same way by the next.

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynid/io/joint_record_file.hpp"

namespace dynid::cli {

/// The values of the run flags as given on the command line.
struct RunFlags {
  double rate = 0.0;                 ///< --rate [Hz]; 0: the file's t column gives the time
  std::string columns;               ///< --columns from=to,... or positions 1=t,2=q1,...
  std::vector<double> torque_scale;  ///< --torque-scale K or K1,...,Kn; empty: 1
  std::string rows;                  ///< --rows A:B (data rows from 1); empty: every row
  std::string time;                  ///< --time T0:T1 [s]; empty: every row
  double time_shift = 0.0;           ///< --time-shift S [s]
  /// --torque-offset S, the old name of --time-shift, as text: a hidden option has no name in
  /// CLI11's own errors, so run_file_options() checks it and names it.
  std::optional<std::string> old_time_shift;
  std::string torque_bias;  ///< --torque-bias J=VALUE,...; empty: no bias
  std::string topic;        ///< --topic of a ROS log; empty: /joint_states or the only one

  /// The time shift [s] given by either name (checked by run_file_options()).
  double shift() const;
};

/// What a command does when a run flag is not given.
enum class RunFlagDefaults {
  kNone,            ///< the flag's own default
  kStoredInParams,  ///< validate: the value given to identify, stored in --params
};

/// Registers --rate, --columns, --torque-scale, --rows, --time, --time-shift (and its hidden old
/// name --torque-offset), --torque-bias and --topic on `cmd`, bound to `flags`.
void add_run_flags(CLI::App* cmd, RunFlags& flags,
                   RunFlagDefaults defaults = RunFlagDefaults::kNone);

/// The library's reading options of `flags` (the time shift is a signal option: SignalOptions::
/// torque_time_offset). Throws dynid::UsageError naming the flag for --rows with --time, a
/// negative or non-finite rate, --time-shift with --torque-offset, and malformed --columns, --rows,
/// --time or --torque-bias text.
RunFileOptions run_file_options(const RunFlags& flags);

/// Whether any run flag of `cmd` was given (`--rate`, ...), by its long name with "--".
bool run_flag_given(const CLI::App& cmd, const char* flag);

}  // namespace dynid::cli
