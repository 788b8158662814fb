#pragma once

// Private parts of the ROS log readers (not installed): one decoded sensor_msgs/JointState, the
// two wire formats, the topic choice and the messages-to-table step every format shares.

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "dynid/io/joint_state_log.hpp"

namespace dynid::ros_detail {

/// One sensor_msgs/JointState message.
struct JointStateMessage {
  std::int64_t stamp_ns = 0;   ///< header.stamp [ns]
  std::int64_t record_ns = 0;  ///< when the log recorded it [ns] (bag time, rostopic %time)
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;
};

/// The messages of one topic of a log.
struct TopicMessages {
  std::string topic;
  std::vector<JointStateMessage> messages;
  std::vector<std::string> notes;
  std::vector<std::string> warnings;
};

/// Decodes a JointState in ROS 1 serialization (little-endian, no padding: Header{uint32 seq,
/// uint32 sec, uint32 nsec, string frame_id}, string[] name, float64[] position, velocity,
/// effort; strings and arrays are a uint32 count then the items). Throws dynid::Error prefixed
/// with `where` for bytes that end early, counts beyond the bytes or kMaxJointStateJoints, and
/// bytes left over.
JointStateMessage decode_ros1_joint_state(const std::uint8_t* data, std::size_t size,
                                          const std::string& where);

/// Decodes a JointState in CDR as the ROS 2 type support writes it (XCDR1): a 4-byte
/// encapsulation header (00 01 little-endian, 00 00 big-endian), then the fields aligned to their
/// size relative to the byte after that header: Time{int32 sec, uint32 nanosec}, string
/// frame_id, sequence<string> name, sequence<float64> position, velocity, effort. A string is a
/// uint32 length counting its terminating NUL, then the bytes; a sequence a uint32 count.
/// Throws dynid::Error prefixed with `where` as decode_ros1_joint_state, and for another
/// encapsulation (XCDR2, parameter lists).
JointStateMessage decode_cdr_joint_state(const std::uint8_t* data, std::size_t size,
                                         const std::string& where);

/// The topic to read among `topics` (name, type) of the log `path`: `requested` when given, else
/// /joint_states, else the log's one topic of `joint_state_type` (with a note in `notes`).
/// Throws dynid::Error naming the JointState topics for an absent topic, a topic of another type,
/// no JointState topic, or several without /joint_states.
std::string choose_topic(const std::vector<std::pair<std::string, std::string>>& topics,
                         const std::string& joint_state_type, const std::string& requested,
                         const std::string& path, std::vector<std::string>& notes);

/// Throws the size-limit error when `values` (messages × columns so far) exceeds
/// kMaxJointStateValues.
void check_value_count(std::size_t values, const std::string& source);

/// The run table of `messages` (read_joint_state_log() documents the columns and the errors).
/// `source` names the file and topic in messages; `what` names a message ("message", "line").
JointStateLog joint_state_table(std::vector<JointStateMessage>& messages, const std::string& source,
                                const std::string& what);

/// ROS 1 bag reader (format 2.0, records scanned in file order; chunks plain, bz2 or lz4): the
/// JointState messages of `topic` (choose_topic()) in record-time order. A file that ends inside
/// a record (an interrupted recording) is read up to it, with a warning.
TopicMessages read_rosbag1(const std::string& path, const std::string& topic);

/// The sqlite3 storage files (`*.db3`) of the ROS 2 bag folder `folder`, sorted; empty when none.
std::vector<std::string> rosbag2_storage_files(const std::string& folder);

/// ROS 2 sqlite3 bag reader: the JointState messages of `topic` (choose_topic()) in record-time
/// order, from the `.db3` file `path` or every `.db3` file of the bag folder `path` (a split bag).
TopicMessages read_rosbag2_sqlite(const std::string& path, const std::string& topic);

}  // namespace dynid::ros_detail
