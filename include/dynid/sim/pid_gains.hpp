#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/model/model.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "dynid/sim/simulate_reference.hpp"

namespace dynid {

/// Reads per-joint PID gains from a YAML (or JSON) file with the keys kp, ki, kd, each a list of
/// one value per joint of `model` in joint order: `kp: [400, 120]`, units N·m/rad, N·m/(rad·s),
/// N·m·s/rad. The informational keys written by write_pid_gains() (controller, joints,
/// sample_time, derivative_filter_time, effort_limit, delay_samples) are accepted and ignored,
/// so a written gains file reads back; `controller` is returned in PidGains::controller. Throws
/// dynid::Error naming the file and the fault: missing or unreadable file, YAML syntax, a missing
/// or unknown key, a list of the wrong length, a value that is not a finite number >= 0.
PidGains read_pid_gains(const std::string& path, const Model& model);

/// The gains file written beside a simulated run: run.csv -> run.gains.json (any other name gets
/// .gains.json appended); validate --mode simulation looks for it there.
std::string gains_file_for_run(const std::string& run_path);

/// The controller `pid` runs with as JSON: controller ("pid", "pid-feedforward" or
/// "computed-torque"), joints (names), kp, ki, kd, sample_time [s], derivative_filter_time [s],
/// effort_limit, delay_samples (the position delay the default rule was made for).
nlohmann::json pid_gains_to_json(const Model& model, const PidOptions& pid, int delay_samples);

/// Writes pid_gains_to_json() to `path` (atomically). Throws dynid::Error when the file cannot be
/// written.
void write_pid_gains(const std::string& path, const Model& model, const PidOptions& pid,
                     int delay_samples);

}  // namespace dynid
