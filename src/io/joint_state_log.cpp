#include "dynid/io/joint_state_log.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string_view>

#include <fast_float/fast_float.h>
#include <sys/stat.h>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/csv_reader.hpp"
#include "io/joint_state_message.hpp"

namespace dynid {
namespace {

using ros_detail::JointStateMessage;

bool ends_with(const std::string& s, std::string_view suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix.data(), suffix.size()) == 0;
}

// Comma-separated fields of one line, blanks around each removed. None of the exporters quotes.
std::vector<std::string> split_fields(std::string_view line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string_view f =
        line.substr(start, comma == std::string_view::npos ? line.npos : comma - start);
    const std::size_t b = f.find_first_not_of(" \t\r");
    f = b == f.npos ? std::string_view() : f.substr(b, f.find_last_not_of(" \t\r") - b + 1);
    fields.emplace_back(f);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

bool is_integer(const std::string& s) {
  return !s.empty() && s.size() < 20 && s.find_first_not_of("0123456789") == std::string::npos;
}

bool is_number(const std::string& s) {
  double x = 0.0;
  const auto r = fast_float::from_chars(s.data(), s.data() + s.size(), x);
  return !s.empty() && r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// The log's text lines (blank lines dropped), each with its 1-based file line.
std::vector<std::pair<long, std::string>> text_lines(const std::string& path) {
  const std::string text = read_regular_file(path, kMaxCsvFileBytes, "ROS CSV log");
  std::vector<std::pair<long, std::string>> lines;
  long line = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    ++line;
    if (end - start > kMaxCsvLineBytes) {
      throw Error(path + ":" + std::to_string(line) + ": longer than " +
                  std::to_string(kMaxCsvLineBytes) + " bytes; the file is not a ROS CSV log");
    }
    std::string s = text.substr(start, end - start);
    if (!s.empty() && s.back() == '\r') s.pop_back();
    if (s.find_first_not_of(" \t") != std::string::npos) lines.emplace_back(line, std::move(s));
    if (static_cast<long>(lines.size()) > kMaxCsvRows) {
      throw Error(path + ": more than " + std::to_string(kMaxCsvRows) +
                  " lines, the limit for reading a CSV file into memory; split the file");
    }
    start = end + 1;
  }
  if (lines.size() < 2 && !lines.empty() && lines.front().second.rfind("%time", 0) == 0) {
    throw Error(path + ": header but no data rows; the topic had no messages");
  }
  if (lines.empty()) throw Error(path + ": empty file; give a log with one message per line");
  return lines;
}

double field_number(const std::string& s, const std::string& at, const std::string& column) {
  double x = 0.0;
  const auto r = fast_float::from_chars(s.data(), s.data() + s.size(), x);
  if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || !std::isfinite(x)) {
    throw Error(at + ": " + column + " '" + printable(s) +
                "' is not a finite number; fix or remove the line");
  }
  return x;
}

// A non-negative integer field no greater than `max` (stamps: nanoseconds, seconds, nanosec).
std::int64_t field_integer(const std::string& s, const std::string& at, const std::string& column,
                           std::int64_t max) {
  std::int64_t x = -1;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), x);
  if (!is_integer(s) || r.ec != std::errc() || r.ptr != s.data() + s.size() || x > max) {
    throw Error(at + ": " + column + " '" + printable(s) + "' is not an integer from 0 to " +
                std::to_string(max) + "; fix or remove the line");
  }
  return x;
}

// Largest stamp [ns] a CSV line may give: ROS times are 32-bit seconds.
constexpr std::int64_t kMaxStampNs = 4'294'967'296LL * 1'000'000'000;

// `rostopic echo -p` output: `%time` (receive time, ns), field.header.stamp (ns), string fields,
// then field.name<i>, field.position<i>, field.velocity<i>, field.effort<i>, one per array item
// of the first message (an empty array has no column).
JointStateLog read_rostopic_csv(const std::string& path) {
  const auto lines = text_lines(path);
  const std::vector<std::string> header = split_fields(lines.front().second);
  std::map<std::string, std::size_t> column;
  for (std::size_t c = 0; c < header.size(); ++c) column.emplace(header[c], c);
  const auto find = [&](const std::string& name) {
    const auto it = column.find(name);
    return it == column.end() ? header.size() : it->second;
  };
  const std::size_t time = find("%time"), stamp = find("field.header.stamp");
  if (stamp == header.size()) {
    throw Error(path +
                ": no field.header.stamp column; export the JointState topic itself "
                "with rostopic echo -p");
  }
  std::map<std::string, std::vector<std::size_t>> arrays;
  for (const char* a : {"name", "position", "velocity", "effort"}) {
    for (std::size_t i = 0;; ++i) {
      const std::size_t c = find(std::string("field.") + a + std::to_string(i));
      if (c == header.size()) break;
      arrays[a].push_back(c);
    }
  }
  std::vector<JointStateMessage> messages;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const std::string at = path + ":" + std::to_string(lines[k].first);
    const std::vector<std::string> f = split_fields(lines[k].second);
    if (f.size() != header.size()) {
      throw Error(at + ": " + std::to_string(f.size()) + " fields, the header has " +
                  std::to_string(header.size()) +
                  "; the arrays changed length during the log (rostopic echo -p names the "
                  "columns after the first message): record a bag instead");
    }
    JointStateMessage m;
    m.stamp_ns = field_integer(f[stamp], at, "field.header.stamp", kMaxStampNs);
    m.record_ns = time < f.size() ? field_integer(f[time], at, "%time", kMaxStampNs) : m.stamp_ns;
    for (const std::size_t c : arrays["name"]) m.name.push_back(f[c]);
    for (const auto& [a, v] :
         {std::pair{"position", &m.position}, std::pair{"velocity", &m.velocity},
          std::pair{"effort", &m.effort}}) {
      const std::vector<std::size_t>& cols = arrays[a];
      // An array left empty in this message prints empty fields.
      if (std::all_of(cols.begin(), cols.end(), [&](std::size_t c) { return f[c].empty(); }))
        continue;
      for (const std::size_t c : cols) v->push_back(field_number(f[c], at, header[c]));
    }
    messages.push_back(std::move(m));
    ros_detail::check_value_count(messages.size() * header.size(), path);
  }
  JointStateLog log = ros_detail::joint_state_table(messages, "'" + path + "'", "message");
  log.notes.insert(log.notes.begin(), "'" + path + "': rostopic echo -p output");
  return log;
}

// `ros2 topic echo --csv` output, no header: sec, nanosec, frame_id, the names, then the
// position, velocity and effort values. The names are the run of non-numeric fields after
// frame_id; the rest must be three arrays of that length, since a headerless line cannot say
// which of velocity and effort an empty array was.
JointStateLog read_ros2_echo_csv(const std::string& path) {
  const auto lines = text_lines(path);
  std::vector<JointStateMessage> messages;
  for (const auto& [line, text] : lines) {
    const std::string at = path + ":" + std::to_string(line);
    const std::vector<std::string> f = split_fields(text);
    std::size_t n = 0;
    while (3 + n < f.size() && !is_number(f[3 + n])) ++n;
    const std::size_t values = f.size() - std::min(f.size(), 3 + n);
    if (n == 0 || values != 3 * n) {
      throw Error(at + ": " + std::to_string(n) + " joint names and " + std::to_string(values) +
                  " values; ros2 topic echo --csv lines are read as sec,nanosec,frame_id, the "
                  "names, then position, velocity and effort with one value per name (all "
                  "three needed: a line without a header cannot say which array is empty); "
                  "record a bag instead");
    }
    JointStateMessage m;
    const std::int64_t nanosec = field_integer(f[1], at, "nanosec", 999'999'999);
    m.stamp_ns =
        field_integer(f[0], at, "sec", kMaxStampNs / 1'000'000'000) * 1'000'000'000 + nanosec;
    m.record_ns = m.stamp_ns;
    m.name.assign(f.begin() + 3, f.begin() + 3 + static_cast<long>(n));
    std::size_t c = 3 + n;
    for (auto* v : {&m.position, &m.velocity, &m.effort}) {
      for (std::size_t j = 0; j < n; ++j, ++c)
        v->push_back(field_number(f[c], at, "field " + std::to_string(c + 1)));
    }
    messages.push_back(std::move(m));
    ros_detail::check_value_count(messages.size() * 3 * n, path);
  }
  JointStateLog log = ros_detail::joint_state_table(messages, "'" + path + "'", "line");
  log.notes.insert(log.notes.begin(), "'" + path + "': ros2 topic echo --csv output");
  return log;
}

// PlotJuggler's CSV export: `__time` [s], then one column per series; a JointState topic gives
// `<topic>/<joint>/position`, `/velocity`, `/effort`. A row has empty cells for the series
// without a sample at its time (series of other topics), so rows missing a joint value are
// times of other topics' samples and are dropped.
JointStateLog read_plotjuggler_csv(const std::string& path, const std::string& requested) {
  const auto lines = text_lines(path);
  const std::vector<std::string> header = split_fields(lines.front().second);
  const auto time =
      static_cast<std::size_t>(std::find(header.begin(), header.end(), "__time") - header.begin());
  // topic -> joint -> column of position, velocity, effort
  std::map<std::string, std::map<std::string, std::array<std::size_t, 3>>> topics;
  const std::array<std::string, 3> kFields = {"/position", "/velocity", "/effort"};
  for (std::size_t c = 0; c < header.size(); ++c) {
    for (std::size_t a = 0; a < 3; ++a) {
      if (!ends_with(header[c], kFields[a])) continue;
      const std::string series = header[c].substr(0, header[c].size() - kFields[a].size());
      const std::size_t slash = series.rfind('/');
      if (slash == std::string::npos || slash == 0) continue;
      const std::array<std::size_t, 3> absent = {header.size(), header.size(), header.size()};
      auto& joints = topics[series.substr(0, slash)];
      joints.try_emplace(series.substr(slash + 1), absent).first->second[a] = c;
    }
  }
  std::vector<std::pair<std::string, std::string>> listed;
  for (const auto& entry : topics) listed.emplace_back(entry.first, "JointState");
  JointStateLog log;
  const std::string topic =
      ros_detail::choose_topic(listed, "JointState", requested, path, log.notes);
  const auto& joints = topics[topic];
  const std::string source = "'" + path + "' topic " + printable(topic);
  CsvTable& table = log.table;
  table.source = source;
  table.columns.push_back("t");
  std::vector<std::size_t> used = {time};
  const std::array<const char*, 3> kPrefix = {"q_", "dq_", "tau_"};
  for (std::size_t a = 0; a < 3; ++a) {
    std::size_t present = 0;
    for (const auto& [joint, cols] : joints) present += cols[a] < header.size();
    if (present == 0 && a == 1) continue;
    for (const auto& [joint, cols] : joints) {
      if (cols[a] >= header.size()) {
        throw Error(source + ": no column " + topic + "/" + printable(joint) + kFields[a] +
                    "; dynid needs the " + (a == 2 ? "effort" : kFields[a].substr(1)) +
                    " of every joint: export it from PlotJuggler with the others");
      }
      table.columns.push_back(kPrefix[a] + joint);
      used.push_back(cols[a]);
    }
  }
  std::vector<double> values;
  std::size_t dropped = 0;
  for (std::size_t k = 1; k < lines.size(); ++k) {
    const std::string at = path + ":" + std::to_string(lines[k].first);
    const std::vector<std::string> f = split_fields(lines[k].second);
    if (f.size() > header.size()) {
      throw Error(at + ": " + std::to_string(f.size()) + " fields, the header has " +
                  std::to_string(header.size()) + "; export the file again");
    }
    if (std::any_of(used.begin(), used.end(),
                    [&](std::size_t c) { return c >= f.size() || f[c].empty(); })) {
      ++dropped;
      continue;
    }
    for (const std::size_t c : used) values.push_back(field_number(f[c], at, header[c]));
    table.lines.push_back(lines[k].first);
    ros_detail::check_value_count(values.size(), path);
  }
  const auto cols = static_cast<Eigen::Index>(used.size());
  const auto rows = static_cast<Eigen::Index>(table.lines.size());
  if (rows == 0) {
    throw Error(source +
                ": no row has every joint's values; export the topic's samples "
                "(PlotJuggler: File > Export to CSV with the JointState series)");
  }
  table.data = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      values.data(), rows, cols);
  log.notes.insert(log.notes.begin(), "'" + path + "': PlotJuggler CSV, " +
                                          std::to_string(joints.size()) + " joints of " +
                                          printable(topic) + ", t = __time");
  if (dropped > 0) {
    log.notes.push_back(std::to_string(dropped) + " rows of '" + path +
                        "' without a sample of every joint (times of other series) dropped");
  }
  return log;
}

}  // namespace

JointStateLogFormat joint_state_log_format(const std::string& path) {
  if (ends_with(path, ".bag")) return JointStateLogFormat::kRosbag1;
  if (ends_with(path, ".db3")) return JointStateLogFormat::kRosbag2Sqlite;
  // Opening a FIFO or a device would block or never end: the CSV reader names those.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return JointStateLogFormat::kNone;
  if (S_ISDIR(st.st_mode)) {
    // A ROS 2 bag is a folder: metadata.yaml and its storage files.
    return !ros_detail::rosbag2_storage_files(path).empty() ||
                   ::stat((path + "/metadata.yaml").c_str(), &st) == 0
               ? JointStateLogFormat::kRosbag2Sqlite
               : JointStateLogFormat::kNone;
  }
  if (!S_ISREG(st.st_mode)) return JointStateLogFormat::kNone;
  std::ifstream in(path, std::ios::binary);
  std::string first;
  // Only the first line decides; a line of a CSV run is far shorter than this.
  char buffer[4096];
  if (!in.read(buffer, sizeof(buffer)) && in.gcount() <= 0) return JointStateLogFormat::kNone;
  first.assign(buffer, static_cast<std::size_t>(in.gcount()));
  first = first.substr(0, first.find('\n'));
  if (first.rfind("%time,field.", 0) == 0) return JointStateLogFormat::kRostopicCsv;
  const std::vector<std::string> f = split_fields(first);
  if (std::find(f.begin(), f.end(), "__time") != f.end())
    return JointStateLogFormat::kPlotJugglerCsv;
  if (f.size() >= 7 && is_integer(f[0]) && is_integer(f[1]) && !f[3].empty() && !is_number(f[3]))
    return JointStateLogFormat::kRos2EchoCsv;
  return JointStateLogFormat::kNone;
}

JointStateLog read_joint_state_log(const std::string& path, JointStateLogFormat format,
                                   const std::string& topic) {
  const auto bag = [&](ros_detail::TopicMessages messages) {
    JointStateLog log = ros_detail::joint_state_table(
        messages.messages, "'" + path + "' topic " + printable(messages.topic), "message");
    log.notes.insert(log.notes.begin(), messages.notes.begin(), messages.notes.end());
    log.warnings.insert(log.warnings.begin(), messages.warnings.begin(), messages.warnings.end());
    return log;
  };
  JointStateLog log;
  switch (format) {
    case JointStateLogFormat::kRosbag1:
      return bag(ros_detail::read_rosbag1(path, topic));
    case JointStateLogFormat::kRosbag2Sqlite:
      return bag(ros_detail::read_rosbag2_sqlite(path, topic));
    case JointStateLogFormat::kRostopicCsv:
      log = read_rostopic_csv(path);
      break;
    case JointStateLogFormat::kRos2EchoCsv:
      log = read_ros2_echo_csv(path);
      break;
    case JointStateLogFormat::kPlotJugglerCsv:
      return read_plotjuggler_csv(path, topic);
    case JointStateLogFormat::kNone:
      throw Error("'" + path +
                  "' is not a ROS log; give a .bag, a .db3 or a CSV exported from "
                  "ROS");
  }
  if (!topic.empty()) {
    log.warnings.push_back("--topic " + printable(topic) + " has no effect: '" + path +
                           "' holds one topic's messages (no topic names)");
  }
  return log;
}

}  // namespace dynid
