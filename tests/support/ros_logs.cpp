#include "support/ros_logs.hpp"

#include <cstring>
#include <stdexcept>

#include <rosbag/bag.h>
#include <sensor_msgs/JointState.h>
#include <sqlite3.h>
#include <std_msgs/String.h>

namespace dynid::testing {

void write_ros1_bag(const std::string& path, const std::vector<TestLogEntry>& entries,
                    BagCompression compression, const std::vector<std::string>& string_topics) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  bag.setCompression(compression == BagCompression::kBz2   ? rosbag::compression::BZ2
                     : compression == BagCompression::kLz4 ? rosbag::compression::LZ4
                                                           : rosbag::compression::Uncompressed);
  // Small chunks, so that the reader crosses chunk boundaries.
  bag.setChunkThreshold(4096);
  for (const TestLogEntry& e : entries) {
    ros::Time received;
    received.fromNSec(static_cast<std::uint64_t>(e.record_ns));
    bool is_string = false;
    for (const std::string& t : string_topics) is_string = is_string || t == e.topic;
    if (is_string) {
      std_msgs::String s;
      s.data = e.message.frame_id;
      bag.write(e.topic, received, s);
      continue;
    }
    sensor_msgs::JointState m;
    m.header.stamp.fromNSec(static_cast<std::uint64_t>(e.message.stamp_ns));
    m.header.frame_id = e.message.frame_id;
    m.name = e.message.name;
    m.position = e.message.position;
    m.velocity = e.message.velocity;
    m.effort = e.message.effort;
    bag.write(e.topic, received, m);
  }
  bag.close();
}

namespace {

// CDR as eProsima Fast-CDR writes it for the ROS 2 type support: every primitive aligned to its
// size, counted from the first byte after the 4-byte encapsulation header.
class CdrWriter {
 public:
  explicit CdrWriter(bool little) : little_(little) {
    bytes_ = {0x00, static_cast<std::uint8_t>(little ? 0x01 : 0x00), 0x00, 0x00};
  }
  void u32(std::uint32_t v) {
    align(4);
    put(&v, 4);
  }
  void f64(double x) {
    align(8);
    put(&x, 8);
  }
  void string(const std::string& s) {
    u32(static_cast<std::uint32_t>(s.size() + 1));
    bytes_.insert(bytes_.end(), s.begin(), s.end());
    bytes_.push_back(0);
  }
  std::vector<std::uint8_t> bytes() const { return bytes_; }

 private:
  void align(std::size_t n) {
    while ((bytes_.size() - 4) % n != 0) bytes_.push_back(0);
  }
  void put(const void* v, std::size_t n) {
    std::uint8_t b[8];
    std::memcpy(b, v, n);
    for (std::size_t i = 0; i < n; ++i) bytes_.push_back(little_ ? b[i] : b[n - 1 - i]);
  }
  bool little_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace

std::vector<std::uint8_t> cdr_joint_state(const TestJointState& m, bool little_endian) {
  CdrWriter w(little_endian);
  w.u32(static_cast<std::uint32_t>(static_cast<std::int32_t>(m.stamp_ns / 1'000'000'000)));
  w.u32(static_cast<std::uint32_t>(m.stamp_ns % 1'000'000'000));
  w.string(m.frame_id);
  w.u32(static_cast<std::uint32_t>(m.name.size()));
  for (const std::string& s : m.name) w.string(s);
  for (const auto* v : {&m.position, &m.velocity, &m.effort}) {
    w.u32(static_cast<std::uint32_t>(v->size()));
    for (const double x : *v) w.f64(x);
  }
  return w.bytes();
}

void write_ros2_db3(const std::string& path, const std::vector<TestTopic>& topics,
                    const std::vector<TestRecord>& records) {
  sqlite3* db = nullptr;
  if (sqlite3_open(path.c_str(), &db) != SQLITE_OK) throw std::runtime_error("sqlite3_open");
  auto exec = [&](const char* sql) {
    if (sqlite3_exec(db, sql, nullptr, nullptr, nullptr) != SQLITE_OK)
      throw std::runtime_error(sqlite3_errmsg(db));
  };
  // No fsync: the tests write many small bags.
  exec("PRAGMA synchronous=OFF; PRAGMA journal_mode=MEMORY;");
  exec(
      "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY, ros_distro TEXT NOT NULL);"
      "INSERT INTO schema VALUES (3, 'humble');"
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
      " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,"
      " timestamp INTEGER NOT NULL, data BLOB NOT NULL);"
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
      "BEGIN;");
  sqlite3_stmt* topic = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO topics VALUES (?, ?, ?, ?, '')", -1, &topic, nullptr);
  for (std::size_t i = 0; i < topics.size(); ++i) {
    sqlite3_bind_int64(topic, 1, static_cast<sqlite3_int64>(i + 1));
    sqlite3_bind_text(topic, 2, topics[i].name.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(topic, 3, topics[i].type.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(topic, 4, topics[i].serialization_format.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_step(topic);
    sqlite3_reset(topic);
  }
  sqlite3_finalize(topic);
  sqlite3_stmt* message = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)", -1,
                     &message, nullptr);
  for (const TestRecord& r : records) {
    sqlite3_bind_int64(message, 1, r.topic + 1);
    sqlite3_bind_int64(message, 2, r.timestamp);
    if (r.data.empty()) {
      sqlite3_bind_zeroblob(message, 3, 0);
    } else {
      sqlite3_bind_blob(message, 3, r.data.data(), static_cast<int>(r.data.size()),
                        SQLITE_TRANSIENT);
    }
    if (sqlite3_step(message) != SQLITE_DONE) throw std::runtime_error(sqlite3_errmsg(db));
    sqlite3_reset(message);
  }
  sqlite3_finalize(message);
  exec("COMMIT;");
  sqlite3_close(db);
}

}  // namespace dynid::testing
