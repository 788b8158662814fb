#include "run_flags.hpp"

#include <cmath>
#include <cstdlib>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/joint_columns.hpp"

namespace dynid::cli {

void add_run_flags(CLI::App* cmd, RunFlags& flags, RunFlagDefaults defaults) {
  // validate remembers these from identify (issue 26 item 3); the help says so once, here.
  const std::string stored = defaults == RunFlagDefaults::kStoredInParams
                                 ? "; default: as given to identify (stored in --params)"
                                 : "";
  cmd->add_option("--rate", flags.rate, "Sample rate [Hz] when the file has no t column" + stored);
  cmd->add_option("--columns", flags.columns,
                  "Rename columns before lookup: from=to,from2=to2; for a file without a header, "
                  "name columns by position counted from 1: 1=t,2=q1,3=q2,..." +
                      stored);
  cmd->add_option("--torque-scale", flags.torque_scale,
                  "tau_j = K_j * logged torque column (e.g. drive gain x current): one value or "
                  "one per joint, comma separated" +
                      stored)
      ->delimiter(',');
  cmd->add_option("--rows", flags.rows,
                  "Use data rows A:B only (counted from 1 after the header, inclusive; A: or :B "
                  "leave an end open)");
  cmd->add_option("--time", flags.time,
                  "Use the samples with T0 <= t <= T1 [s] only (T0: or :T1 open)");
  cmd->add_option("--time-shift", flags.time_shift,
                  "The torque logged at t acts at t + S [s]: half the sample period for a command "
                  "held over the next step (dynid simulate), -d for a sensor lagging d" +
                      stored);
  // The name before issue 26 item 7 (it shifts time, it offsets no torque): kept, not shown.
  cmd->add_option("--torque-offset", flags.old_time_shift, "Old name of --time-shift")->group("");
  cmd->add_option("--torque-bias", flags.torque_bias,
                  "Constant sensor bias subtracted from the logged torque: J=VALUE,... (J a joint "
                  "number from 1 or a joint name, VALUE [N m] on the joint side, after "
                  "--torque-scale). To estimate it instead, keep identify's offset friction term "
                  "(--friction ...,offset, the default): Fo<j> is that bias plus any other "
                  "constant torque" +
                      stored);
  cmd->add_option("--topic", flags.topic,
                  "sensor_msgs/JointState topic of a ROS log given as the run (.bag, .db3, "
                  "PlotJuggler export); default /joint_states, or the log's only JointState topic" +
                      stored);
}

RunFileOptions run_file_options(const RunFlags& flags) {
  if (!flags.rows.empty() && !flags.time.empty()) {
    throw UsageError("give --rows or --time, not both: they both choose the window of the run");
  }
  if (!(flags.rate >= 0.0) || !std::isfinite(flags.rate)) {
    throw UsageError("--rate must be a positive sample rate in Hz");
  }
  if (flags.old_time_shift) {
    if (flags.time_shift != 0.0)
      throw UsageError("give --time-shift only: --torque-offset is its old name");
    char* end = nullptr;
    const double x = std::strtod(flags.old_time_shift->c_str(), &end);
    if (end == flags.old_time_shift->c_str() || *end != '\0' || !std::isfinite(x)) {
      throw UsageError("--torque-offset '" + printable(*flags.old_time_shift) +
                       "' is not a finite time in seconds; give --time-shift S (its new name)");
    }
  }
  RunFileOptions file;
  file.columns = parse_column_mapping(flags.columns);
  file.rate_hz = flags.rate;
  file.torque_scale = flags.torque_scale;
  if (!flags.rows.empty()) file.window = parse_run_window(flags.rows, false, "--rows");
  if (!flags.time.empty()) file.window = parse_run_window(flags.time, true, "--time");
  file.torque_bias = parse_torque_bias(flags.torque_bias);
  file.topic = flags.topic;
  return file;
}

double RunFlags::shift() const {
  return old_time_shift ? std::strtod(old_time_shift->c_str(), nullptr) : time_shift;
}

bool run_flag_given(const CLI::App& cmd, const char* flag) {
  // The old name of --time-shift counts as it.
  if (std::string(flag) == "--time-shift" && cmd.count("--torque-offset")) return true;
  return cmd.count(flag) > 0;
}

}  // namespace dynid::cli
