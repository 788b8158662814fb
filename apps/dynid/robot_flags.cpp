#include "robot_flags.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/csv_chunk_reader.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/io/joint_state_log.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/report/stored_result.hpp"

namespace dynid::cli {
namespace {

std::vector<JointLock> parse_locks(const std::vector<std::string>& items) {
  std::vector<JointLock> locks;
  for (const std::string& item : items) {
    const auto eq = item.find('=');
    const std::string name = eq == std::string::npos ? item : item.substr(0, eq);
    const std::string text = eq == std::string::npos ? "" : item.substr(eq + 1);
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (name.empty() || text.empty() || *end != '\0' || !std::isfinite(value)) {
      throw UsageError("--lock '" + printable(item) +
                       "' is not NAME=VALUE; give the joint's name and the position it is held "
                       "at [rad or m], e.g. --lock gripper_joint=0.02");
    }
    locks.push_back({name, value});
  }
  return locks;
}

std::string lock_list(const std::vector<JointLock>& locks) {
  std::string s;
  for (const JointLock& l : locks)
    s += (s.empty() ? "" : ", ") + l.name + "=" + short_number(l.value);
  return s;
}

std::string joint_list(const Model& model) {
  std::string s;
  for (const Joint& j : model.joints) s += (s.empty() ? "" : ", ") + j.name;
  return s;
}

// The robot's joints the first run's header names as q_<name>, in model order (so the tree
// order holds); empty when the header names none, or all, has numbered position columns, or
// cannot be read (the command's own reading reports that).
std::vector<std::string> joints_of_header(const Model& model, const RobotContext& context) {
  if (context.runs.empty() || columns_by_position(context.columns)) return {};
  std::vector<std::string> header;
  try {
    // A ROS log's names are in its messages: it is read once more here.
    const std::string& run = context.runs.front();
    const JointStateLogFormat format = joint_state_log_format(run);
    header = format == JointStateLogFormat::kNone
                 ? CsvChunkReader(run).columns()
                 : read_joint_state_log(run, format, context.topic).table.columns;
  } catch (const Error&) {
    return {};
  }
  for (auto& name : header) {
    for (const auto& [from, to] : context.columns)
      if (name == from) name = to;
  }
  // A numbered position column (q1, qm2) counts joints by model index: the log then names
  // joints by number, not by name, and nothing is matched.
  for (const std::string& c : header) {
    for (const std::string prefix : {"q", "qm"}) {
      if (c.size() > prefix.size() && c.compare(0, prefix.size(), prefix) == 0 &&
          c.find_first_not_of("0123456789", prefix.size()) == std::string::npos)
        return {};
    }
  }
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  const std::vector<std::string> named = joints_named_in_columns(header, names);
  if (named.empty() || named.size() == names.size()) return {};
  std::vector<std::string> kept;
  for (const std::string& n : names)
    if (std::find(named.begin(), named.end(), n) != named.end()) kept.push_back(n);
  return kept;
}

}  // namespace

void add_robot_flags(CLI::App* cmd, RobotFlags& flags, RobotFlagDefaults defaults) {
  const bool stored = defaults == RobotFlagDefaults::kStoredInParams;
  cmd->add_option(
         "--joints", flags.joints,
         "The robot's joints the log holds, in the log's order (comma separated names): "
         "joint j of the log (q<j>, tau<j>) is the j-th; every other moving joint is "
         "held fixed at its --lock value and its links' inertia merges into the link "
         "carrying it. Default: " +
             std::string(stored ? "the joints identify used (stored in --params), else " : "") +
             "the joints the log's header names as q_<name>, else all")
      ->delimiter(',');
  cmd->add_option(
         "--lock", flags.locks,
         "NAME=VALUE: a joint not identified is held at VALUE [rad or m], at 0 when not "
         "named; repeat or comma separate; alone, it locks the named joints and keeps "
         "the rest" +
             std::string(stored ? ". Default: the locks identify used (stored in --params)" : ""))
      ->delimiter(',');
  cmd->add_flag("--strict", flags.strict,
                "Refuse a robot file whose link inertia is not physical (not positive "
                "semi-definite or breaking the triangle inequality) or whose <limit> lacks effort "
                "or velocity; default: load it with one warning each (vendor URDFs break the "
                "triangle inequality by a few percent; the limit is read as unlimited)");
}

JointSelection selection_stored_in(const std::string& params) {
  JointSelection s;
  if (params.empty()) return s;
  try {
    const IdentifiedResultFile f = read_identification_result(params);
    if (!f.locked_joints.empty()) {
      s.joints = f.joints;
      s.locks = f.locked_joints;
    } else {
      s.joints = ResultFileOptions{f.options, params}.get("joints", std::vector<std::string>{});
    }
  } catch (const Error&) {
    return {};
  }
  return s;
}

Model load_cli_robot(const std::string& robot, const RobotFlags& flags,
                     const RobotContext& context) {
  JointSelection selection;
  selection.joints = flags.joints;
  selection.locks = parse_locks(flags.locks);
  RobotOptions options;
  options.strict = flags.strict;
  LoadedRobot loaded = load_robot(robot, options);
  for (const std::string& w : loaded.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  std::string from;
  if (selection.empty() && !context.stored.empty()) {
    try {
      loaded.model = lock_joints(loaded.model, context.stored);
    } catch (
        const Error& e) {  // a result's joints may not fit this robot: say where they came from
      throw Error(std::string(e.what()) + " (the joints identify used, stored in '" +
                  context.stored_from + "'; give --joints and --lock for this robot)");
    }
    from = "(as identified: stored in '" + context.stored_from + "')";
  } else if (selection.empty()) {
    selection.joints = joints_of_header(loaded.model, context);
    if (!selection.joints.empty()) {
      from = "(not in '" + context.runs.front() + "'; --joints and --lock choose)";
    }
  }
  loaded.model = lock_joints(loaded.model, selection);
  if (!loaded.model.locked_joints.empty()) {
    std::cerr << context.command << ": locked joints" << (from.empty() ? "" : " ") << one_line(from)
              << ": " << one_line(lock_list(loaded.model.locked_joints))
              << "; identified joints: " << one_line(joint_list(loaded.model)) << '\n';
  }
  return loaded.model;
}

}  // namespace dynid::cli
