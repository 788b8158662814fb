#include "partial_support.hpp"

#include "dynid/common/error.hpp"

namespace dynid::cli {

nlohmann::json partial_options(nlohmann::json echo) {
  echo.erase("data");
  echo.erase("robot");
  return echo;
}

Model load_part_robot(const StreamPartial& part, const std::string& path, const std::string& robot,
                      const RobotFlags& flags, std::string& used) {
  JointSelection stored;
  used = stream_partial_robot(part, stored);
  if (!robot.empty()) {
    used = robot;
    return load_cli_robot(used, flags, {"merge", {}, {}, stored, path});
  }
  try {
    return load_cli_robot(used, flags, {"merge", {}, {}, stored, path});
  } catch (const UsageError&) {
    throw;  // the command line's own flags (--lock text)
  } catch (const Error& e) {
    // The path was valid where the part was made, maybe not here.
    throw Error(std::string(e.what()) + " (the robot '" + used + "' that '" + path +
                "' names; give --robot with its path on this machine)");
  }
}

IdentificationResult solve_merged_part(const Model& model, const StreamPartial& part) {
  try {
    return solve_stream_partial(model, part);
  } catch (const NormalEquationsError& e) {
    throw Error(std::string(e.what()) +
                "; re-make the parts with identify --stream --householder --partial");
  }
}

}  // namespace dynid::cli
