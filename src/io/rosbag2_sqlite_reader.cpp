// ROS 2 bags in rosbag2's sqlite3 storage: tables topics(id, name, type, serialization_format,
// ...) and messages(id, topic_id, timestamp, data), data in CDR (docs/methods/io.md).

#include <memory>
#include <vector>

#include <sys/stat.h>

#include <sqlite3.h>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"
#include "io/joint_state_message.hpp"

namespace dynid::ros_detail {
namespace {

constexpr const char* kJointStateType = "sensor_msgs/msg/JointState";

struct StatementCloser {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Statement = std::unique_ptr<sqlite3_stmt, StatementCloser>;

struct DatabaseCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};

std::string column_text(sqlite3_stmt* s, int c) {
  const unsigned char* text = sqlite3_column_text(s, c);
  return text ? reinterpret_cast<const char*>(text) : "";
}

}  // namespace

TopicMessages read_rosbag2_sqlite(const std::string& path, const std::string& requested) {
  require_regular_file(path, "ROS 2 bag");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw Error("ROS 2 bag '" + path + "' does not exist; check the path given to --data");
  }
  sqlite3* raw = nullptr;
  // Read-only and without creating anything: a missing or foreign file must not become an empty
  // database, and a reader must not leave a journal next to the user's bag.
  const int opened =
      sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr);
  std::unique_ptr<sqlite3, DatabaseCloser> db(raw);
  auto fail = [&](const std::string& what) {
    throw Error("ROS 2 bag '" + path + "' cannot be read (" + what + ": " +
                printable(db ? sqlite3_errmsg(db.get()) : "out of memory") +
                "); give the .db3 file of a ROS 2 bag recorded with the sqlite3 storage");
  };
  if (opened != SQLITE_OK) fail("open");
  auto prepare = [&](const char* sql) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db.get(), sql, -1, &s, nullptr) != SQLITE_OK) {
      sqlite3_finalize(s);
      fail("query");
    }
    return Statement(s);
  };
  TopicMessages out;
  std::vector<std::pair<std::string, std::string>> topics;
  std::vector<std::pair<sqlite3_int64, std::string>> ids;  // topic id, serialization format
  {
    Statement s = prepare("SELECT id, name, type, serialization_format FROM topics");
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
      topics.emplace_back(column_text(s.get(), 1), column_text(s.get(), 2));
      ids.emplace_back(sqlite3_column_int64(s.get(), 0), column_text(s.get(), 3));
    }
    if (rc != SQLITE_DONE) fail("topics");
  }
  out.topic = choose_topic(topics, kJointStateType, requested, path, out.notes);
  const std::string source = "'" + path + "' topic " + printable(out.topic);
  std::vector<sqlite3_int64> wanted;
  for (std::size_t i = 0; i < topics.size(); ++i) {
    if (topics[i].first != out.topic) continue;
    if (ids[i].second != "cdr") {
      throw Error(source + " is serialized as '" + printable(ids[i].second) +
                  "', not 'cdr'; record it with the default serialization");
    }
    wanted.push_back(ids[i].first);
  }
  Statement s =
      prepare("SELECT timestamp, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id");
  std::size_t values = 0;
  for (const sqlite3_int64 id : wanted) {
    sqlite3_reset(s.get());
    sqlite3_bind_int64(s.get(), 1, id);
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
      const std::string where = source + " message " + std::to_string(out.messages.size() + 1);
      const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(s.get(), 1));
      const auto size = static_cast<std::size_t>(sqlite3_column_bytes(s.get(), 1));
      if (size > kMaxJointStateBytes) {
        throw Error(where + ": " + std::to_string(size) + " bytes, beyond the " +
                    std::to_string(kMaxJointStateBytes) +
                    "-byte limit of one JointState; the bag is corrupt");
      }
      JointStateMessage m = decode_cdr_joint_state(data, data ? size : 0, where);
      m.record_ns = sqlite3_column_int64(s.get(), 0);
      values += 3 * m.name.size();
      check_value_count(values, source);
      out.messages.push_back(std::move(m));
    }
    if (rc != SQLITE_DONE) fail("messages");
  }
  return out;
}

}  // namespace dynid::ros_detail
