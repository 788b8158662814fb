#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/closed_loop/closed_loop.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// The reference columns of a run file (`qr*`, optional `dqr*`, `ddqr*`, docs/design.md §4), sample
/// for sample with `run` as read_joint_record() read it from the same file and options (the same
/// --columns mapping and --rows/--time window). No `qr*` column gives an empty record (the
/// closed-loop preparation names the missing columns). Throws dynid::Error naming the file when
/// the run's samples are not found in it.
ReferenceRecord read_reference_columns(const std::string& path, const Model& model,
                                       const RunFileOptions& options, const JointRecord& run);

/// Sensor noise per joint from the JSON of `dynid average --json` (channels q<j>, tau<j> or
/// q_<joint>, tau_<joint>): the noise of the data identify fits. When `data` is the mean period
/// the file names as its `out` (same file on disk), the field std_averaged (the mean's noise,
/// averaged_noise_std()); otherwise std (the raw per-sample noise). `which`, if given, receives
/// one line saying which and why. Throws dynid::Error naming the file for a missing channel or
/// field, or a std that is not a finite number >= 0.
SensorNoise read_sensor_noise(const std::string& path, const Model& model,
                              const std::string& data = "", std::string* which = nullptr);

/// Sensor noise per joint from the parsed JSON of `dynid average --json` (or the dict of the
/// Python average()): channels q<j>, tau<j> or q_<joint>, tau_<joint>, their std_averaged (the
/// mean period's noise) when `averaged`, else std (the raw per-sample noise). `name` names the
/// input in messages. Throws dynid::Error for no channels list, a missing channel or field, or a
/// std that is not a finite number >= 0.
SensorNoise sensor_noise_from_json(const nlohmann::json& j, const Model& model, bool averaged,
                                   const std::string& name);

/// `--noise-std q=S,tau=S` (one value for every joint each; either may be omitted). Throws
/// dynid::UsageError for anything else or a value that is not finite and >= 0.
SensorNoise parse_noise_std(const std::string& text, int joints);

/// The result JSON's `closed_loop` entry: method, M1, M2, correlation (per joint), the remainder
/// test, dimensions per channel; spectral: f0, period, lines, energy above the band. Per run
/// under `runs` when there are several.
nlohmann::json closed_loop_to_json(const std::vector<ClosedLoopReport>& reports);

/// The result JSON's `repeated` entry: n, level, and per parameter name, mean, std, ci_half_width.
nlohmann::json repeated_to_json(const RepeatedEstimate& repeated, const std::string& over);

}  // namespace dynid
