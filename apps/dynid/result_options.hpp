#pragma once

// identify's options as a result JSON of `dynid identify` records them, for the commands that
// apply an identified model to another run (validate, payload --reference result.json).

#include <optional>
#include <string>
#include <vector>

#include "dynid/estimation/identification.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/report/identification_report.hpp"

namespace dynid::cli {

/// What the caller's own flags set instead of the file (validate's --cutoff, --zero-velocity,
/// --torque-scale).
struct ResultOptionOverrides {
  std::optional<double> cutoff;       ///< low-pass cut-off [Hz]; unset: the one identify used
  std::vector<double> zero_velocity;  ///< per joint [rad/s]; empty: the thresholds identify used
  bool torque_scale_given = false;    ///< true: keep file.torque_scale as the caller set it
};

/// The IdentifyOptions that rebuild identify's regressor and signal processing from `identified`
/// (read from `path`): friction set, armature, filter, the cut-off and zero-velocity thresholds
/// identify used, Savitzky–Golay, torque offset, filtered Coulomb columns; file.torque_scale as
/// given to identify unless overridden. Notes go to read.notes. Throws dynid::Error naming `path`
/// and the option for a value of the wrong type or an invalid option in the file.
IdentifyOptions options_from_identification_result(const IdentifiedResultFile& identified,
                                                   const std::string& path, int dof,
                                                   const ResultOptionOverrides& overrides,
                                                   RunFileOptions& file, RunFileReport& read);

}  // namespace dynid::cli
