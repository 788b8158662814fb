#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "dynid/io/csv_table.hpp"

namespace dynid {

/// Input limits of the ROS log readers (docs/cli.md, "Input size limits"): beyond them the
/// readers throw dynid::Error instead of exhausting memory.
inline constexpr std::size_t kMaxJointStateBytes = std::size_t{1} << 20;   ///< one message
inline constexpr std::size_t kMaxJointStateJoints = 4096;                  ///< names per message
inline constexpr std::size_t kMaxJointStateValues = std::size_t{1} << 27;  ///< messages × columns

/// How a run file records `sensor_msgs/JointState` messages (docs/methods/io.md, "ROS logs").
enum class JointStateLogFormat {
  kNone,           ///< not a ROS log: a plain CSV run (docs/design.md §4)
  kRosbag1,        ///< ROS 1 bag (`.bag`, format 2.0; chunks plain, bz2 or lz4)
  kRosbag2Sqlite,  ///< ROS 2 bag in sqlite3 storage (`.db3`, or its folder), messages in CDR
  kRostopicCsv,    ///< `rostopic echo -p` output: header `%time,field.header.seq,...`
  kRos2EchoCsv,    ///< `ros2 topic echo --csv` output: no header, sec,nanosec,frame_id,names,...
  kPlotJugglerCsv  ///< PlotJuggler CSV export: `__time`, `<topic>/<joint>/position` ...
};

/// The format of the run file `path`: by extension for bags (`.bag`, `.db3`; a folder with `.db3`
/// files or a metadata.yaml is a ROS 2 bag), else by the first
/// line of the text (`%time,field.` for rostopic, a `__time` column for PlotJuggler, two integers
/// followed by a name for ros2 topic echo); kNone for anything else, including a file that cannot
/// be read (the CSV reader then reports why). Reads at most the first line. Never throws.
JointStateLogFormat joint_state_log_format(const std::string& path);

/// A log's JointState messages as a run table, and what reading it chose.
struct JointStateLog {
  /// Columns `t` [s] (header stamps minus the first one), `q_<name>`, `dq_<name>` when the messages
  /// carry velocities, `tau_<name>`, one per joint name in the first message's order; one row per
  /// message, in stamp order. `source` is "PATH topic TOPIC".
  CsvTable table;
  std::vector<std::string> notes;     ///< the topic chosen, the time origin, skipped messages
  std::vector<std::string> warnings;  ///< choices the user should check (receive time used)
};

/// Reads the `sensor_msgs/JointState` messages of `topic` from the ROS log `path` of `format`
/// (joint_state_log_format()). An empty `topic` takes /joint_states, or the log's one JointState
/// topic when it has no /joint_states (said in a note). The time column is header.stamp minus the
/// first message's stamp, computed in integer nanoseconds; when every stamp is zero (a publisher
/// that never sets it) the record time of the log is used instead, with a warning. Messages on
/// the topic that name none of the first message's joints (a second publisher, e.g. a gripper)
/// are skipped with a note. Names map to columns exactly as a CSV's `q_<name>` columns do, so
/// the joints are matched to the model by resolve_joint_columns().
/// Throws dynid::Error (one line naming the file, the topic and the fix) for: a file that is not
/// a readable log of its format (corrupt, truncated, unindexed), a topic that is absent or not
/// JointState (lists the JointState topics), no messages, a message whose arrays disagree in
/// length with its names or that lists a joint twice, joints that change between messages,
/// empty position or effort arrays (names the missing field), stamps that do not increase
/// strictly (names the two messages), NaN or Inf values, and input beyond the limits above.
JointStateLog read_joint_state_log(const std::string& path, JointStateLogFormat format,
                                   const std::string& topic);

}  // namespace dynid
