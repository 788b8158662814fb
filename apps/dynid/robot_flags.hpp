#pragma once

// The flags that say how to load the robot for a run (issue 26 items 1 and 4): one definition
// and one help text for every command that takes --robot, so that a robot file with more moving
// joints than the log (a gripper, a head, a mobile base) and a vendor URDF with a slightly
// non-physical inertia load the same way in every command.

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "dynid/io/joint_columns.hpp"
#include "dynid/model/joint_lock.hpp"
#include "dynid/model/model.hpp"

namespace dynid::cli {

/// The values of the robot flags as given on the command line.
struct RobotFlags {
  std::vector<std::string> joints;  ///< --joints a,b,c: the joints identified, in the log's order
  std::vector<std::string> locks;   ///< --lock NAME=VALUE (repeatable, or comma separated)
  bool strict = false;              ///< --strict: refuse a non-physical link inertia
};

/// What a command does when neither --joints nor --lock is given.
enum class RobotFlagDefaults {
  kNone,            ///< the joints the run's header names, else every joint
  kStoredInParams,  ///< validate, export, ...: the joints locked by identify, stored in --params
};

/// Registers --joints, --lock and --strict on `cmd`, bound to `flags`.
void add_robot_flags(CLI::App* cmd, RobotFlags& flags,
                     RobotFlagDefaults defaults = RobotFlagDefaults::kNone);

/// Where the joint selection may come from besides the flags.
struct RobotContext {
  std::string command;            ///< prefix of the lines said on stderr ("identify")
  std::vector<std::string> runs;  ///< runs whose header (or ROS log) may name the joints
  ColumnMapping columns;          ///< --columns renames applied to those headers first
  JointSelection stored;          ///< the selection a result was identified with (stored_selection)
  std::string stored_from;        ///< that result's path, named in the note
  std::string topic{};            ///< --topic of a run that is a ROS log (its names are read)
};

/// The robot `robot` (built-in name or path) loaded for a command: a non-physical inertia is a
/// warning on stderr (an error with --strict); the joints not identified are locked (lock_joints)
/// as --joints/--lock say, else as `context.stored` says, else — when the first run's header
/// names some of the robot's joints as q_<name> — every joint it does not name is held at 0; the
/// locked joints and their values are said on stderr. Throws dynid::UsageError for malformed
/// --lock text and dynid::Error for every error of load_robot and lock_joints.
/// The selection the result JSON `params` was identified with: its `model.joints` and
/// `locked_joints` when it locked joints, else its `options.joints` (a reordering only); empty
/// when `params` is empty, names no result, or the result locked nothing (the command reads and
/// reports the file itself).
JointSelection selection_stored_in(const std::string& params);

Model load_cli_robot(const std::string& robot, const RobotFlags& flags,
                     const RobotContext& context);

}  // namespace dynid::cli
