#pragma once

// Writers of the ROS logs the tests read (compiled once in support/ros_logs.cpp, so that the ROS
// headers stay out of the test files): ROS 1 bags written by rosbag_storage itself with
// sensor_msgs::JointState serialized by its generated code, and ROS 2 sqlite3 bags built with
// sqlite3 from CDR bytes laid out here by hand, as the ROS 2 type support writes them.

#include <cstdint>
#include <string>
#include <vector>

namespace dynid::testing {

/// One sensor_msgs/JointState as the tests write it.
struct TestJointState {
  std::int64_t stamp_ns = 0;  ///< header.stamp [ns]
  std::string frame_id;
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;
};

/// One message of a log: its topic, the time the recorder received it [ns], the message.
struct TestLogEntry {
  std::string topic;
  std::int64_t record_ns = 0;
  TestJointState message;
};

enum class BagCompression { kNone, kBz2, kLz4 };

/// Writes a ROS 1 bag with rosbag::Bag: every entry as sensor_msgs::JointState; entries whose
/// topic is in `string_topics` as std_msgs::String holding the frame_id instead.
void write_ros1_bag(const std::string& path, const std::vector<TestLogEntry>& entries,
                    BagCompression compression = BagCompression::kNone,
                    const std::vector<std::string>& string_topics = {});

/// The CDR bytes of `m` (encapsulation header included), little- or big-endian.
std::vector<std::uint8_t> cdr_joint_state(const TestJointState& m, bool little_endian = true);

/// A topic of a ROS 2 bag and its type (`sensor_msgs/msg/JointState`).
struct TestTopic {
  std::string name, type, serialization_format = "cdr";
};

/// One stored message: topic index into the topics, receive time [ns], bytes.
struct TestRecord {
  int topic = 0;
  std::int64_t timestamp = 0;
  std::vector<std::uint8_t> data;
};

/// Writes a rosbag2 sqlite3 storage file (schema of rosbag2_storage_default_plugins: topics and
/// messages tables) with sqlite3.
void write_ros2_db3(const std::string& path, const std::vector<TestTopic>& topics,
                    const std::vector<TestRecord>& records);

}  // namespace dynid::testing
