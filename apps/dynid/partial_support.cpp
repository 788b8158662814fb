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
  if (!robot.empty()) used = robot;
  return load_cli_robot(used, flags, {"merge", {}, {}, stored, path});
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
