#include "io/joint_state_message.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <unordered_map>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

namespace dynid::ros_detail {
namespace {

// A bounded cursor over a message's bytes. `origin` is where CDR alignment counts from.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size, std::size_t origin, bool swap,
             const std::string& where)
      : data_(data), size_(size), origin_(origin), pos_(origin), swap_(swap), where_(where) {}

  void align(std::size_t n) {
    const std::size_t off = (pos_ - origin_) % n;
    if (off != 0) skip(n - off);
  }
  std::uint32_t u32() {
    std::uint32_t v = 0;
    copy(&v, 4);
    return swap_ ? __builtin_bswap32(v) : v;
  }
  double f64() {
    std::uint64_t v = 0;
    copy(&v, 8);
    if (swap_) v = __builtin_bswap64(v);
    double x = 0.0;
    std::memcpy(&x, &v, 8);
    return x;
  }
  // A count of items of at least `item_bytes` bytes each, checked against what is left so that
  // a corrupt count cannot allocate beyond the message.
  std::size_t count(std::size_t item_bytes, const char* field) {
    const std::size_t n = u32();
    if (item_bytes > 1 && n > kMaxJointStateJoints) {
      throw Error(where_ + ": " + field + " count " + std::to_string(n) + " is beyond " +
                  std::to_string(kMaxJointStateJoints) +
                  " joints, the limit for one message; the log is corrupt or not of a robot arm");
    }
    if (n * item_bytes > size_ - pos_) {
      throw Error(where_ + ": " + field + " count " + std::to_string(n) + " is beyond the " +
                  std::to_string(size_ - pos_) +
                  " bytes left in the message; the log is corrupt, record it again");
    }
    return n;
  }
  std::string text(std::size_t n) {
    need(n);
    std::string s(reinterpret_cast<const char*>(data_ + pos_), n);
    pos_ += n;
    return s;
  }
  void skip(std::size_t n) {
    need(n);
    pos_ += n;
  }
  std::size_t left() const { return size_ - pos_; }

 private:
  void need(std::size_t n) const {
    if (n > size_ - pos_) {
      throw Error(where_ + ": the message ends after " + std::to_string(size_) +
                  " bytes, inside a field; the log is truncated or corrupt, record it again");
    }
  }
  void copy(void* out, std::size_t n) {
    need(n);
    std::memcpy(out, data_ + pos_, n);
    pos_ += n;
  }

  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t origin_;
  std::size_t pos_;
  bool swap_;
  const std::string& where_;
};

void expect_end(const ByteReader& r, const std::string& where, std::size_t tolerated) {
  // CDR may pad the end to 4 or 8 bytes; anything more is not a JointState.
  if (r.left() > tolerated) {
    throw Error(where + ": " + std::to_string(r.left()) +
                " bytes are left after the JointState fields; the topic's messages are not "
                "sensor_msgs/JointState");
  }
}

}  // namespace

JointStateMessage decode_ros1_joint_state(const std::uint8_t* data, std::size_t size,
                                          const std::string& where) {
  ByteReader r(data, size, 0, false, where);
  JointStateMessage m;
  r.u32();  // seq
  const std::uint32_t sec = r.u32();
  const std::uint32_t nsec = r.u32();
  m.stamp_ns = static_cast<std::int64_t>(sec) * 1'000'000'000 + nsec;
  r.skip(r.count(1, "frame_id length"));
  m.name.resize(r.count(4, "name"));
  for (std::string& s : m.name) s = r.text(r.count(1, "name length"));
  for (auto* v : {&m.position, &m.velocity, &m.effort}) {
    v->resize(r.count(8, "array"));
    for (double& x : *v) x = r.f64();
  }
  expect_end(r, where, 0);
  return m;
}

JointStateMessage decode_cdr_joint_state(const std::uint8_t* data, std::size_t size,
                                         const std::string& where) {
  if (size < 4 || data[0] != 0 || data[1] > 1) {
    char head[32] = "";
    if (size >= 2) std::snprintf(head, sizeof(head), "%02x %02x", data[0], data[1]);
    throw Error(where + ": the message's CDR encapsulation is '" + head +
                "', not plain CDR (00 00 or 00 01); dynid reads the CDR the ROS 2 type support "
                "writes by default");
  }
  const bool little = data[1] == 1;
  ByteReader r(data, size, 4, !little, where);
  JointStateMessage m;
  const auto sec = static_cast<std::int32_t>(r.u32());
  const std::uint32_t nanosec = r.u32();
  m.stamp_ns = static_cast<std::int64_t>(sec) * 1'000'000'000 + nanosec;
  auto string = [&](const char* field) {
    r.align(4);
    const std::size_t n = r.count(1, field);
    std::string s = r.text(n);
    // The length counts the terminating NUL; an empty string may be written without one.
    if (!s.empty()) s.pop_back();
    return s;
  };
  string("frame_id length");
  r.align(4);
  m.name.resize(r.count(5, "name"));
  for (std::string& s : m.name) s = string("name length");
  for (auto* v : {&m.position, &m.velocity, &m.effort}) {
    r.align(4);
    v->resize(r.count(8, "array"));
    if (!v->empty()) r.align(8);
    for (double& x : *v) x = r.f64();
  }
  expect_end(r, where, 7);
  return m;
}

std::string choose_topic(const std::vector<std::pair<std::string, std::string>>& topics,
                         const std::string& joint_state_type, const std::string& requested,
                         const std::string& path, std::vector<std::string>& notes) {
  std::vector<std::string> joint_state;
  for (const auto& [name, type] : topics) {
    if (type == joint_state_type &&
        std::find(joint_state.begin(), joint_state.end(), name) == joint_state.end())
      joint_state.push_back(name);
  }
  std::string list;
  for (const std::string& t : joint_state) list += (list.empty() ? "" : ", ") + t;
  const std::string available = joint_state.empty()
                                    ? "it has no " + joint_state_type + " topic"
                                    : "its " + joint_state_type + " topics: " + printable(list);
  if (!requested.empty()) {
    for (const auto& [name, type] : topics) {
      if (name == requested && type != joint_state_type) {
        throw Error("'" + path + "' topic " + printable(requested) + " is " + printable(type) +
                    ", not " + joint_state_type + " (" + available +
                    "); give a JointState topic with --topic");
      }
    }
    if (std::find(joint_state.begin(), joint_state.end(), requested) == joint_state.end()) {
      throw Error("'" + path + "' has no topic " + printable(requested) + " (" + available +
                  "); give one of them with --topic");
    }
    return requested;
  }
  if (std::find(joint_state.begin(), joint_state.end(), "/joint_states") != joint_state.end())
    return "/joint_states";
  if (joint_state.size() == 1) {
    notes.push_back("topic " + printable(joint_state.front()) + ": the log's only " +
                    joint_state_type + " topic (no /joint_states; --topic chooses)");
    return joint_state.front();
  }
  if (joint_state.empty()) {
    throw Error("'" + path + "' has no " + joint_state_type +
                " topic; record the robot's joint states (e.g. /joint_states) in the log");
  }
  throw Error("'" + path + "' has " + std::to_string(joint_state.size()) + " " + joint_state_type +
              " topics and no /joint_states (" + printable(list) + "); choose one with --topic");
}

void check_value_count(std::size_t values, const std::string& source) {
  if (values > kMaxJointStateValues) {
    throw Error(source + ": more than " + std::to_string(kMaxJointStateValues) +
                " joint values, the limit for reading a log into memory; cut the log (e.g. "
                "rosbag filter, ros2 bag convert) or split it");
  }
}

JointStateLog joint_state_table(std::vector<JointStateMessage>& messages, const std::string& source,
                                const std::string& what) {
  JointStateLog log;
  if (messages.empty()) {
    throw Error(source +
                ": no JointState messages; record the topic, or choose another with "
                "--topic");
  }
  const std::vector<std::string> names = messages.front().name;
  const std::size_t n = names.size();
  if (n == 0) {
    throw Error(source + ": the first " + what +
                " names no joints (empty name array); dynid matches the joints to the robot by "
                "name: publish the names");
  }
  std::unordered_map<std::string, std::size_t> index;
  for (std::size_t j = 0; j < n; ++j) {
    if (!index.emplace(names[j], j).second) {
      throw Error(source + ": the first " + what + " names joint '" + printable(names[j]) +
                  "' twice; each joint must appear once");
    }
  }
  const bool velocity = !messages.front().velocity.empty();
  std::vector<const JointStateMessage*> kept;
  std::vector<long> numbers;
  std::size_t skipped = 0;
  std::string skipped_example;
  for (std::size_t k = 0; k < messages.size(); ++k) {
    JointStateMessage& m = messages[k];
    const std::string at = source + " " + what + " " + std::to_string(k + 1);
    std::size_t known = 0;
    for (const std::string& s : m.name) known += index.count(s);
    if (known == 0 && !m.name.empty()) {
      // Another publisher's joints on the same topic (a gripper's driver, say).
      ++skipped;
      if (skipped_example.empty()) skipped_example = m.name.front();
      continue;
    }
    if (known != n || m.name.size() != n) {
      std::string list;
      for (const std::string& s : m.name) list += (list.empty() ? "" : ",") + s;
      throw Error(at + " names the joints " + printable(list) + ", not the " + std::to_string(n) +
                  " joints of the first message; the joints must not change during the log");
    }
    const auto check = [&](std::vector<double>& v, const char* field, bool required) {
      if (v.empty() && !required) return;
      if (v.empty()) {
        throw Error(at + ": the " + std::string(field) + " array is empty; dynid needs joint " +
                    (std::string(field) == "effort" ? "torques" : "positions") +
                    " for every joint: record them in the JointState messages (field " + field +
                    ")");
      }
      if (v.size() != n) {
        throw Error(at + ": " + std::to_string(v.size()) + " " + field + " values for " +
                    std::to_string(n) +
                    " names; the arrays of a JointState have one value per "
                    "name");
      }
      std::vector<double> ordered(n);
      for (std::size_t j = 0; j < n; ++j) {
        if (!std::isfinite(v[j])) {
          throw Error(at + ": " + field + " of joint '" + printable(m.name[j]) +
                      "' is not a finite number; remove the message or fix the log");
        }
        ordered[index[m.name[j]]] = v[j];
      }
      v.swap(ordered);
    };
    check(m.position, "position", true);
    if (velocity && m.velocity.empty()) {
      throw Error(at +
                  ": the velocity array is empty but the first message has velocities; "
                  "the fields must not change during the log");
    }
    check(m.velocity, "velocity", velocity);
    if (!velocity) m.velocity.clear();
    check(m.effort, "effort", true);
    kept.push_back(&m);
    numbers.push_back(static_cast<long>(k + 1));
  }
  if (skipped > 0) {
    log.notes.push_back(std::to_string(skipped) + " " + what + "s of " + source +
                        " name other joints (e.g. '" + printable(skipped_example) +
                        "') and were skipped");
  }
  bool unset = true;
  for (const JointStateMessage* m : kept) unset = unset && m->stamp_ns == 0;
  if (unset && kept.size() > 1) {
    log.warnings.push_back("every header.stamp of " + source +
                           " is zero (the publisher does not set it): t is the time the log "
                           "recorded each message, which includes transport delays");
  }
  auto stamp = [&](const JointStateMessage* m) { return unset ? m->record_ns : m->stamp_ns; };
  for (std::size_t k = 1; k < kept.size(); ++k) {
    if (stamp(kept[k]) <= stamp(kept[k - 1])) {
      char buffer[160];
      std::snprintf(buffer, sizeof(buffer), "%.9f s is not after %.9f s of %s %ld",
                    stamp(kept[k]) * 1e-9, stamp(kept[k - 1]) * 1e-9, what.c_str(), numbers[k - 1]);
      throw Error(source + " " + what + " " + std::to_string(numbers[k]) + ": " +
                  (unset ? "record time " : "header.stamp ") + buffer +
                  "; time must be strictly increasing: remove repeated or reordered messages");
    }
  }
  const std::int64_t origin = stamp(kept.front());
  char first[64];
  std::snprintf(first, sizeof(first), "%lld.%09lld", static_cast<long long>(origin / 1'000'000'000),
                static_cast<long long>(origin % 1'000'000'000));
  log.notes.push_back(source + ": " + std::to_string(n) +
                      " joints, t = " + (unset ? "record time" : "header.stamp") + " - " + first +
                      " s (the first message's)" +
                      (velocity ? "" : "; no velocities (derived from the positions)"));
  CsvTable& table = log.table;
  table.source = source;
  table.columns.push_back("t");
  for (const char* prefix : {"q_", "dq_", "tau_"}) {
    if (std::string(prefix) == "dq_" && !velocity) continue;
    for (const std::string& s : names) table.columns.push_back(prefix + s);
  }
  const auto rows = static_cast<Eigen::Index>(kept.size());
  table.data.resize(rows, static_cast<Eigen::Index>(table.columns.size()));
  for (Eigen::Index i = 0; i < rows; ++i) {
    const JointStateMessage& m = *kept[static_cast<std::size_t>(i)];
    Eigen::Index c = 0;
    table.data(i, c++) = static_cast<double>(stamp(&m) - origin) * 1e-9;
    for (const auto* v : {&m.position, &m.velocity, &m.effort}) {
      for (const double x : *v) table.data(i, c++) = x;
    }
    table.lines.push_back(numbers[static_cast<std::size_t>(i)]);
  }
  return log;
}

}  // namespace dynid::ros_detail
