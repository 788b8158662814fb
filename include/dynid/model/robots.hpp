#pragma once

#include <string>
#include <vector>

#include "dynid/model/joint_lock.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// Folder holding the built-in robots, the first of: $DYNID_ROBOTS_DIR if set and non-empty; the
/// robots installed with the code, found relative to the file that holds it, so that a moved
/// install prefix keeps them: for a shared library or Python extension <its dir>/../share/dynid/
/// robots or <its dir>/robots, for a program <dir of /proc/self/exe>/../share/dynid/robots; else
/// the source tree's DYNID_SOURCE_DIR "/examples/robots" (compile definition of robots.cpp).
/// Never throws; the folder may not exist (builtin_robot_names() is then empty).
std::string builtin_robots_dir();

/// Short names of the built-in robots (file stems of the *.urdf, *.yaml, *.yml files in
/// builtin_robots_dir()), sorted. Empty when the folder is missing.
std::vector<std::string> builtin_robot_names();

/// Loads a robot by short name or path and returns a finalized Model. A short name (no '/' and no
/// '.') is a built-in: builtin_robots_dir()/<name>.yaml, .yml or .urdf; its Model::name is the
/// short name. A path ending in .urdf goes to load_urdf, .yaml/.yml to load_yaml_model.
/// Model::source is the file that was read. Throws dynid::Error for an unknown built-in (the
/// message lists the built-in names), an unsupported extension, and every loader error.
Model load_robot(const std::string& name_or_path);

/// How a robot is loaded for a run (the CLI's --joints, --lock, --strict; Python's load_model).
struct RobotOptions {
  JointSelection selection;  ///< joints identified and joints locked (lock_joints); empty: all
  /// false (default): a non-physical link inertia loads with a warning (vendor URDFs break the
  /// triangle inequality by a few percent); true: it is an error.
  bool strict = false;
};

/// A loaded robot and what loading it said.
struct LoadedRobot {
  Model model;  ///< finalized, with the selection applied (Model::locked_joints)
  std::vector<std::string> warnings;  ///< one line per non-physical link inertia tolerated
};

/// load_robot(name_or_path) with `options`: the inertia check as options.strict says, then
/// lock_joints(model, options.selection). Throws as load_robot and lock_joints.
LoadedRobot load_robot(const std::string& name_or_path, const RobotOptions& options);

}  // namespace dynid
