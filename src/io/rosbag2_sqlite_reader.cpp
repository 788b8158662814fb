// ROS 2 bags in rosbag2's sqlite3 storage: tables topics(id, name, type, serialization_format,
// ...) and messages(id, topic_id, timestamp, data), data in CDR (docs/methods/io.md).

#include <algorithm>
#include <filesystem>
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

namespace {

// One storage file: its database and topics (name, type), ids and serialization formats.
struct Db3 {
  std::string path;
  std::unique_ptr<sqlite3, DatabaseCloser> db;
  std::vector<std::pair<std::string, std::string>> topics;
  std::vector<std::pair<sqlite3_int64, std::string>> ids;

  [[noreturn]] void fail(const std::string& what) const {
    throw Error("ROS 2 bag '" + path + "' cannot be read (" + what + ": " +
                printable(db ? sqlite3_errmsg(db.get()) : "out of memory") +
                "); give the .db3 file (or the folder) of a ROS 2 bag recorded with the sqlite3 "
                "storage");
  }
  Statement prepare(const char* sql) const {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db.get(), sql, -1, &s, nullptr) != SQLITE_OK) {
      sqlite3_finalize(s);
      fail("query");
    }
    return Statement(s);
  }
};

Db3 open_db3(const std::string& path) {
  require_regular_file(path, "ROS 2 bag");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw Error("ROS 2 bag '" + path + "' does not exist; check the path given to --data");
  }
  Db3 f;
  f.path = path;
  sqlite3* raw = nullptr;
  // Read-only and without creating anything: a missing or foreign file must not become an empty
  // database, and a reader must not leave a journal next to the user's bag.
  const int opened =
      sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, nullptr);
  f.db.reset(raw);
  if (opened != SQLITE_OK) f.fail("open");
  Statement s = f.prepare("SELECT id, name, type, serialization_format FROM topics");
  int rc = SQLITE_ROW;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    f.topics.emplace_back(column_text(s.get(), 1), column_text(s.get(), 2));
    f.ids.emplace_back(sqlite3_column_int64(s.get(), 0), column_text(s.get(), 3));
  }
  if (rc != SQLITE_DONE) f.fail("topics");
  return f;
}

// Appends the messages of `topic` in `f` to `out`; `values` counts the joint values read.
void read_messages(const Db3& f, const std::string& topic, const std::string& source,
                   std::size_t& values, std::vector<JointStateMessage>& out) {
  Statement s =
      f.prepare("SELECT timestamp, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id");
  for (std::size_t i = 0; i < f.topics.size(); ++i) {
    if (f.topics[i].first != topic) continue;
    if (f.ids[i].second != "cdr") {
      throw Error(source + " is serialized as '" + printable(f.ids[i].second) +
                  "', not 'cdr'; record it with the default serialization");
    }
    sqlite3_reset(s.get());
    sqlite3_bind_int64(s.get(), 1, f.ids[i].first);
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
      const std::string where = source + " message " + std::to_string(out.size() + 1);
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
      out.push_back(std::move(m));
    }
    if (rc != SQLITE_DONE) f.fail("messages");
  }
}

}  // namespace

std::vector<std::string> rosbag2_storage_files(const std::string& folder) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
    if (e.path().extension() == ".db3") files.push_back(e.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

TopicMessages read_rosbag2_sqlite(const std::string& path, const std::string& requested) {
  std::error_code ec;
  const bool folder = std::filesystem::is_directory(path, ec);
  const std::vector<std::string> files =
      folder ? rosbag2_storage_files(path) : std::vector<std::string>{path};
  if (files.empty()) {
    throw Error("ROS 2 bag folder '" + path +
                "' has no .db3 file; dynid reads the sqlite3 storage (an MCAP bag converts with "
                "ros2 bag convert)");
  }
  std::vector<Db3> dbs;
  std::vector<std::pair<std::string, std::string>> topics;
  for (const std::string& f : files) {
    dbs.push_back(open_db3(f));
    topics.insert(topics.end(), dbs.back().topics.begin(), dbs.back().topics.end());
  }
  TopicMessages out;
  out.topic = choose_topic(topics, kJointStateType, requested, path, out.notes);
  const std::string source = "'" + path + "' topic " + printable(out.topic);
  std::size_t values = 0;
  for (const Db3& f : dbs) read_messages(f, out.topic, source, values, out.messages);
  if (dbs.size() > 1) {
    // A split bag: its files follow each other in time, but the order is the timestamps'.
    std::stable_sort(out.messages.begin(), out.messages.end(),
                     [](const JointStateMessage& a, const JointStateMessage& b) {
                       return a.record_ns < b.record_ns;
                     });
    out.notes.push_back(source + ": " + std::to_string(dbs.size()) +
                        " storage files of a split bag read");
  }
  return out;
}

}  // namespace dynid::ros_detail
