#pragma once

// What `identify --stream --partial` and `dynid merge` share (issue 31 item 1): the options a part
// stores and compares, where its robot came from, and the solve of a part with the command
// line's fix for ill-conditioned normal equations.

#include <string>

#include <nlohmann/json.hpp>

#include "dynid/identification/streaming_partial.hpp"
#include "dynid/model/model.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {

/// identify's option echo without what names one run or one host (`data`, `robot`): what two
/// parts must share to merge.
nlohmann::json partial_options(nlohmann::json echo);

/// The robot a part was made with: `robot` when given (another host's path), else the one
/// part.origin names (stream_partial_robot), with the selection it stores unless `flags` select
/// joints themselves; `used` receives the robot's name or path. Throws as load_cli_robot and
/// stream_partial_robot.
Model load_part_robot(const StreamPartial& part, const std::string& path, const std::string& robot,
                      const RobotFlags& flags, std::string& used);

/// solve_stream_partial() with NormalEquationsError turned into the command line's fix (re-make
/// the parts with --householder).
IdentificationResult solve_merged_part(const Model& model, const StreamPartial& part);

}  // namespace dynid::cli
