#include "dynid/io/joint_record_file.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/joint_state_log.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/signal/differentiation.hpp"

namespace dynid {
namespace {

std::string number(double x) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.6g", x);
  return buf;
}

// One end of a window: empty text = open; else a finite number (an integer ≥ 1 for rows).
std::optional<double> window_end(const std::string& text, bool by_time, const std::string& flag,
                                 const std::string& whole) {
  if (text.find_first_not_of(" \t") == std::string::npos) return std::nullopt;
  const std::string usage = by_time ? "T0:T1 in seconds, e.g. --time 2.5:8 (T0: or :T1 leave an "
                                      "end open)"
                                    : "A:B, data rows counted from 1 after the header, e.g. "
                                      "--rows 1001:5000 (A: or :B leave an end open)";
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || std::string(end).find_first_not_of(" \t") != std::string::npos ||
      !std::isfinite(x)) {
    throw UsageError(flag + " '" + whole + "': '" + text + "' is not a finite number; give " +
                     usage);
  }
  if (!by_time && (x < 1.0 || x != std::floor(x) || x > 1e15)) {
    throw UsageError(flag + " '" + whole + "': '" + text +
                     "' is not a row number (an integer >= 1); give " + usage);
  }
  return x;
}

// Rows [first, last] of `t` kept by the window; throws naming the run's extent when it is outside
// the run or keeps fewer than 2 rows.
std::pair<Eigen::Index, Eigen::Index> window_rows(const RunWindow& w, const Eigen::VectorXd& t,
                                                  const std::string& path) {
  const Eigen::Index m = t.size();
  if (!w.by_time) {
    const Eigen::Index first = w.first ? static_cast<Eigen::Index>(*w.first) : 1;
    const Eigen::Index last = w.last ? static_cast<Eigen::Index>(*w.last) : m;
    if (last > m || first > m) {
      throw UsageError("--rows " + std::to_string(first) + ":" + std::to_string(last) + ": '" +
                       path + "' has " + std::to_string(m) +
                       " data rows; give rows within 1:" + std::to_string(m));
    }
    if (last - first + 1 < 2) {
      throw UsageError("--rows keeps " + std::to_string(last - first + 1) + " row of '" + path +
                       "'; a run needs at least 2 rows, give a longer window");
    }
    return {first - 1, last - 1};
  }
  const double t0 = w.first ? *w.first : -INFINITY;
  const double t1 = w.last ? *w.last : INFINITY;
  Eigen::Index first = 0;
  while (first < m && t[first] < t0) ++first;
  Eigen::Index last = m - 1;
  while (last >= 0 && t[last] > t1) --last;
  if (last - first + 1 < 2) {
    throw UsageError("--time " + (w.first ? number(t0) : std::string()) + ":" +
                     (w.last ? number(t1) : std::string()) + " keeps " +
                     std::to_string(std::max<Eigen::Index>(last - first + 1, 0)) + " rows of '" +
                     path + "', whose time runs from " + number(t[0]) + " to " + number(t[m - 1]) +
                     " s; give a window inside that span");
  }
  return {first, last};
}

// Per-joint torque scale (1 or n finite non-zero values).
Eigen::VectorXd torque_scale(const std::vector<double>& k, int n) {
  if (k.empty()) return Eigen::VectorXd::Ones(n);
  if (k.size() != 1 && static_cast<int>(k.size()) != n) {
    throw UsageError("--torque-scale takes 1 or " + std::to_string(n) +
                     " values (one per joint), got " + std::to_string(k.size()));
  }
  for (const double x : k) {
    if (!std::isfinite(x) || x == 0.0) {
      throw UsageError("--torque-scale value " + number(x) +
                       " is not a finite non-zero number; give the gain that turns the logged "
                       "column into N·m (e.g. the torque constant times the gear ratio)");
    }
  }
  return k.size() == 1 ? Eigen::VectorXd::Constant(n, k[0])
                       : Eigen::Map<const Eigen::VectorXd>(k.data(), n).eval();
}

}  // namespace

RunWindow parse_run_window(const std::string& text, bool by_time, const std::string& flag) {
  const auto colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos) {
    throw UsageError(
        flag + " '" + text + "' is not " + (by_time ? "T0:T1" : "A:B") +
        (by_time ? " (seconds, e.g. --time 2.5:8)" : " (data rows from 1, e.g. --rows 1001:5000)"));
  }
  RunWindow w;
  w.by_time = by_time;
  w.first = window_end(text.substr(0, colon), by_time, flag, text);
  w.last = window_end(text.substr(colon + 1), by_time, flag, text);
  if (w.first && w.last && !(*w.first < *w.last)) {
    throw UsageError(flag + " '" + text + "': the first end must be before the last");
  }
  return w;
}

bool columns_by_position(const ColumnMapping& mapping) {
  std::size_t positions = 0;
  for (const auto& [from, to] : mapping) {
    const bool digits = from.find_first_not_of("0123456789") == std::string::npos;
    if (digits && from[0] == '0') {
      throw UsageError("--columns position '" + from +
                       "': positions are counted from 1 (1 = first column)");
    }
    positions += digits;
  }
  if (positions != 0 && positions != mapping.size()) {
    throw UsageError(
        "--columns mixes positions and names; give positions only (1=t,2=q1,... for a file "
        "without a header, counted from 1) or header names only (from=to)");
  }
  return positions != 0;
}

std::vector<std::pair<std::string, double>> parse_torque_bias(const std::string& text) {
  std::vector<std::pair<std::string, double>> entries;
  const std::string usage =
      "; give J=VALUE per joint, J a joint number from 1 or a joint name, VALUE in N m, e.g. "
      "--torque-bias 1=0.3,3=-0.12";
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    std::string item =
        text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? text.size() + 1 : comma + 1;
    const auto first = item.find_first_not_of(" \t");
    if (first == std::string::npos) continue;
    item = item.substr(first, item.find_last_not_of(" \t") - first + 1);
    const auto eq = item.find('=');
    const std::string joint = eq == std::string::npos ? "" : item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    char* end = nullptr;
    const double x = std::strtod(value.c_str(), &end);
    if (joint.empty() || value.empty() || end == value.c_str() ||
        std::string(end).find_first_not_of(" \t") != std::string::npos || !std::isfinite(x)) {
      throw UsageError("--torque-bias entry '" + printable(item) + "' is not J=VALUE" + usage);
    }
    for (const auto& e : entries) {
      if (e.first == joint) {
        throw UsageError("--torque-bias names joint '" + printable(joint) +
                         "' twice; give each joint one bias");
      }
    }
    entries.emplace_back(joint, x);
  }
  return entries;
}

namespace {

// The bias vector of `entries` for joints named `names` (numbers from 1 always work) of `robot`.
Eigen::VectorXd bias_of_joints(const std::vector<std::string>& names, const std::string& robot,
                               const std::vector<std::pair<std::string, double>>& entries) {
  const int n = static_cast<int>(names.size());
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  for (const auto& [joint, value] : entries) {
    int j = -1;
    if (joint.find_first_not_of("0123456789") == std::string::npos && joint.size() < 9) {
      j = std::atoi(joint.c_str()) - 1;
      if (j < 0 || j >= n) {
        throw UsageError("--torque-bias joint " + joint + " is not a joint of " + robot +
                         "; give 1 to " + std::to_string(n) + " or a joint name");
      }
    } else {
      for (int k = 0; k < n; ++k)
        if (names[static_cast<std::size_t>(k)] == joint) j = k;
      if (j < 0) {
        std::string list;
        for (const std::string& k : names) list += (list.empty() ? "" : ", ") + k;
        throw UsageError("--torque-bias joint '" + printable(joint) + "' is not a joint of " +
                         robot + " (" + printable(list) + "); give its number or name");
      }
    }
    b[j] = value;
  }
  return b;
}

}  // namespace

Eigen::VectorXd torque_bias_vector(const Model& model,
                                   const std::vector<std::pair<std::string, double>>& entries) {
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  return bias_of_joints(names, "'" + model.name + "'", entries);
}

void scale_torque_columns(RunTable& run, const RunFileOptions& options, RunFileReport& report) {
  if (options.torque_scale.empty() && options.torque_bias.empty()) return;
  CsvTable& table = run.table;
  const char* prefix = table.find("taum1") ? "taum" : "tau";
  std::vector<Eigen::Index> columns;
  std::vector<std::string> numbers;
  for (int j = 1;; ++j) {
    const auto c = table.find(prefix + std::to_string(j));
    if (!c) break;
    columns.push_back(*c);
    numbers.push_back(std::to_string(j));
  }
  const int n = static_cast<int>(columns.size());
  if (n == 0) {
    throw UsageError("--torque-scale and --torque-bias act on the columns tau1..taun, which '" +
                     table.source + "' does not have; rename its torque columns with --columns");
  }
  const Eigen::VectorXd k = torque_scale(options.torque_scale, n);
  const Eigen::VectorXd b =
      bias_of_joints(numbers,
                     "'" + table.source + "' (columns " + prefix + "1.." + prefix +
                         std::to_string(n) + ", no robot names the joints)",
                     options.torque_bias);
  for (int j = 0; j < n; ++j) {
    table.data.col(columns[static_cast<std::size_t>(j)]) =
        (table.data.col(columns[static_cast<std::size_t>(j)]) * k[j]).array() - b[j];
  }
  report.notes.push_back(std::string(prefix) + "_j = K_j * column - b_j (--torque-scale, " +
                         "--torque-bias) on " + prefix + "1.." + prefix + std::to_string(n));
}

RunTable read_run_table(const std::string& path, const RunFileOptions& options, RunFileReport& out,
                        bool need_time) {
  const bool positional = columns_by_position(options.columns);
  RunTable run;
  CsvTable& table = run.table;
  const JointStateLogFormat format = joint_state_log_format(path);
  if (format != JointStateLogFormat::kNone) {
    if (positional) {
      throw UsageError("--columns by position is for a CSV file without a header; '" + path +
                       "' is a ROS log whose columns are named q_<joint>, dq_<joint>, "
                       "tau_<joint>: rename by name (from=to) or drop --columns");
    }
    JointStateLog log = read_joint_state_log(path, format, options.topic);
    table = std::move(log.table);
    out.notes.insert(out.notes.end(), log.notes.begin(), log.notes.end());
    out.warnings.insert(out.warnings.end(), log.warnings.begin(), log.warnings.end());
  } else {
    if (!options.topic.empty()) {
      out.warnings.push_back("--topic " + printable(options.topic) + " has no effect: '" + path +
                             "' is a CSV run, not a ROS log");
    }
    table = positional ? read_csv_without_header(path) : read_csv(path);
  }
  apply_column_mapping(table, options.columns);
  out.notes.push_back("read " + std::to_string(table.rows()) + " rows of '" + path + "'" +
                      (positional ? " (no header: columns by position, counted from 1)" : ""));
  Eigen::VectorXd& t = run.t;
  if (const auto tc = checked_time_column(table)) {
    t = table.data.col(*tc);
    if (options.rate_hz > 0.0) {
      (options.rate_given ? out.warnings : out.notes)
          .push_back((options.rate_given ? "--rate " + number(options.rate_hz)
                                         : "the stored rate " + number(options.rate_hz) + " Hz") +
                     " has no effect: '" + path + "' has a time column t, which is used");
    }
  } else if (options.rate_hz > 0.0) {
    t = Eigen::VectorXd::LinSpaced(table.rows(), 0.0, (table.rows() - 1) / options.rate_hz);
    out.notes.push_back("time from " +
                        std::string(options.rate_given ? "--rate " : "the stored rate ") +
                        number(options.rate_hz) + " Hz (no t column)");
  } else if (need_time || options.window.by_time) {
    throw UsageError("'" + path +
                     "' has no time column 't'; add one or give the sample rate with --rate HZ");
  }
  if (!options.window.empty()) {
    const Eigen::VectorXd rows =
        t.size() == table.rows()
            ? t
            : Eigen::VectorXd::LinSpaced(table.rows(), 1.0, double(table.rows()));
    const auto [first, last] = window_rows(options.window, rows, path);
    const Eigen::Index kept = last - first + 1;
    out.notes.push_back(
        "window: rows " + std::to_string(first + 1) + ".." + std::to_string(last + 1) + " kept (" +
        std::to_string(kept) + " of " + std::to_string(rows.size()) +
        (t.size() ? "; t = " + number(t[first]) + ".." + number(t[last]) + " s" : std::string()) +
        "), the rest dropped by " + (options.window.by_time ? "--time" : "--rows"));
    table.data = table.data.middleRows(first, kept).eval();
    if (!table.lines.empty()) {
      table.lines = std::vector<long>(table.lines.begin() + first, table.lines.begin() + last + 1);
    }
    if (t.size()) t = t.segment(first, kept).eval();
  }
  return run;
}

JointRecord read_joint_record(const std::string& path, const Model& model,
                              const RunFileOptions& options, RunFileReport* report) {
  const int n = model.dof();
  const Eigen::VectorXd scale = torque_scale(options.torque_scale, n);
  const Eigen::VectorXd bias = torque_bias_vector(model, options.torque_bias);
  RunFileReport local;
  RunFileReport& out = report ? *report : local;
  RunTable run = read_run_table(path, options, out);
  const CsvTable& table = run.table;
  const Eigen::VectorXd& t = run.t;
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  auto has = [&](const char* prefix) { return has_joint_columns(table.columns, names, prefix); };
  JointRecord r;
  r.t = t;
  const bool joint_q = has("q"), motor_q = has("qm");
  if (joint_q && motor_q) {
    throw Error("'" + path +
                "' has both q* and qm* columns; keep one side or rename with --columns");
  }
  if (!joint_q && !motor_q) {
    // Let the resolver produce its precise message about the missing joint columns.
    joint_signal(table, names, "q");
  }
  r.q = joint_q ? joint_signal(table, names, "q")
                : joint_positions_from_motor(model, joint_signal(table, names, "qm"));
  const bool joint_tau = has("tau"), motor_tau = has("taum");
  if (joint_tau && motor_tau) {
    throw Error("'" + path +
                "' has both tau* and taum* columns; keep one side or rename with --columns");
  }
  if (motor_q) out.notes.push_back("positions: qm* (motor side) through the transmission");
  const Eigen::MatrixXd logged = joint_signal(table, names, motor_tau ? "taum" : "tau");
  const Eigen::MatrixXd scaled = logged * scale.asDiagonal();
  r.tau = motor_tau ? joint_torques_from_motor(model, scaled) : scaled;
  if (motor_tau) out.notes.push_back("torques: taum* (motor side) through the transmission");
  if (!options.torque_scale.empty()) {
    std::string k;
    for (int j = 0; j < n; ++j) k += (j ? "," : "") + number(scale[j]);
    out.notes.push_back(std::string("torque scale: ") + (motor_tau ? "taum_j" : "tau_j") +
                        " = K_j * column, K = " + k);
  }
  if (!options.torque_bias.empty()) {
    // A constant sensor bias is known here, not estimated: the offset friction term Fo would
    // estimate it instead (and absorb any other constant torque with it).
    r.tau.rowwise() -= bias.transpose();
    std::string b;
    for (int j = 0; j < n; ++j) b += (j ? "," : "") + number(bias[j]);
    out.notes.push_back("torque bias: tau_j -= b_j (--torque-bias), b = " + b);
  }
  if (has("dq")) r.dq = joint_signal(table, names, "dq");
  if (has("ddq")) r.ddq = joint_signal(table, names, "ddq");
  return r;
}

JointRecord read_reference(const std::string& path, const Model& model,
                           const RunFileOptions& options) {
  CsvTable table = read_csv(path);
  apply_column_mapping(table, options.columns);
  const auto t = checked_time_column(table);
  if (!t)
    throw Error("'" + path + "' has no time column 't'; write the reference with dynid excite");
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  JointRecord r;
  r.t = table.data.col(*t);
  r.q = joint_signal(table, names, "q");
  r.dq = has_joint_columns(table.columns, names, "dq") ? joint_signal(table, names, "dq")
                                                       : central_difference(r.t, r.q, 1);
  r.ddq = has_joint_columns(table.columns, names, "ddq") ? joint_signal(table, names, "ddq")
                                                         : central_difference(r.t, r.dq, 1);
  return r;
}

}  // namespace dynid
