#pragma once

#include <optional>
#include <string>
#include <vector>

#include "dynid/identification/record.hpp"
#include "dynid/io/joint_columns.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// A window of a run: data rows first..last (1-based, inclusive; the first data row after the
/// header is row 1), or time stamps t0 ≤ t ≤ t1 [s]. Unset ends are open.
struct RunWindow {
  bool by_time = false;               ///< false: rows; true: time
  std::optional<double> first, last;  ///< row numbers (integers ≥ 1) or times [s]
  bool empty() const { return !first && !last; }
};

/// How to read a recorded run (docs/design.md §4).
struct RunFileOptions {
  /// Renames applied before lookup (`--columns from=to,...`). When every `from` is a positive
  /// integer the file is read without a header and `from` is a 1-based column position
  /// (`1=t,2=q1,...`).
  ColumnMapping columns;
  double rate_hz = 0.0;  ///< sample rate when the file has no `t` column [Hz]; 0 = need `t`
  /// τ = K_j·(torque column j), e.g. drive gain × current: empty = 1, one value for every joint,
  /// or n values. Applied to the column as logged (motor side for taum*), before the transmission.
  std::vector<double> torque_scale;
  RunWindow window;  ///< part of the run kept (`--rows A:B`, `--time T0:T1`); empty = all
  /// Constant sensor bias b_j subtracted from joint j's torque (`--torque-bias J=VALUE,...`): J is
  /// a joint number counted from 1 or a joint name, VALUE [N·m, or N for a prismatic joint] on the
  /// joint side, after the torque scale and the transmission. Joints not named keep 0.
  std::vector<std::pair<std::string, double>> torque_bias;
  /// The ROS topic of sensor_msgs/JointState messages read from a ROS log (`--topic`; bags and
  /// PlotJuggler exports name topics): empty = /joint_states, or the log's only JointState topic.
  std::string topic;
  /// false when rate_hz is not the user's (a rate stored in a result): a t column that makes it
  /// useless is then a note, not a warning about a flag nobody gave.
  bool rate_given = true;
};

/// A run's table after the file options that need no robot model: columns renamed (or named by
/// position), time from `t` or the rate, the window kept (read_run_table()).
struct RunTable {
  CsvTable table;     ///< the kept rows, columns as renamed
  Eigen::VectorXd t;  ///< time stamps [s] of the kept rows; empty when the run has none
};

/// What read_joint_record did, for the echo on stderr: notes (one line per processing choice) and
/// warnings (options that had no effect).
struct RunFileReport {
  std::vector<std::string> notes;
  std::vector<std::string> warnings;
};

/// Parses `--rows A:B` (1-based inclusive data rows; A: or :B leave an end open) or, with
/// `by_time`, `--time T0:T1` [s]. Throws dynid::UsageError naming `flag` for text that is not
/// two numbers around ':', non-integer or < 1 rows, NaN/Inf, or a first end after the last.
RunWindow parse_run_window(const std::string& text, bool by_time, const std::string& flag);

/// Parses `--torque-bias J=VALUE,...` (J a joint number from 1 or a joint name). Throws
/// dynid::UsageError naming the flag for an entry that is not J=VALUE with a finite VALUE, or a
/// joint given twice.
std::vector<std::pair<std::string, double>> parse_torque_bias(const std::string& text);

/// The per-joint bias vector of `entries` (parse_torque_bias()) for `model`. Throws
/// dynid::UsageError naming --torque-bias and the model's joints for a J that is no joint.
Eigen::VectorXd torque_bias_vector(const Model& model,
                                   const std::vector<std::pair<std::string, double>>& entries);

/// For a command without a robot model (average): options.torque_scale and options.torque_bias
/// (joints by number only) applied to the numbered columns tau1..taun (or taum1..taumn) of `run`,
/// n their count; nothing without either option. Throws dynid::UsageError naming the flag when
/// the table has no such columns, for a count that is not 1 or n, or a joint that is not 1..n.
void scale_torque_columns(RunTable& run, const RunFileOptions& options, RunFileReport& report);

/// Reads `path` as a run with the options that need no model: options.columns, time from `t` or
/// options.rate_hz, options.window. A ROS log (joint_state_log_format(): `.bag`, `.db3`,
/// `rostopic echo -p`, `ros2 topic echo --csv` or PlotJuggler CSV) is read by
/// read_joint_state_log() from options.topic into the columns t, q_<name>, dq_<name>, tau_<name>
/// first; --columns by position is then a dynid::UsageError (the log names its joints). With
/// `need_time` false a run without time information is read with an empty RunTable::t (a --time
/// window then needs one). Throws as read_joint_record(). Notes and warnings go to `report`.
/// Commands that read other columns than a joint record's (payload's wrench, average's every
/// column) read their run through this.
RunTable read_run_table(const std::string& path, const RunFileOptions& options,
                        RunFileReport& report, bool need_time = true);

/// True when `--columns` names columns by position only (every `from` a positive integer);
/// throws dynid::UsageError when positions and names are mixed.
bool columns_by_position(const ColumnMapping& mapping);

/// Reads a run into a joint-side record: time from `t` (or `rate_hz`), positions from `q*`
/// (joint side) or `qm*` (motor side, converted with the model's transmission,
/// q = N⁻¹·qm + q_offset), torques from `tau*` or `taum*` (tau = Nᵀ·taum), and `dq*`, `ddq*` when
/// present (used as given). Columns `q<j>` or `q_<joint name>`; other columns ignored.
/// Then keeps options.window, scales the torques by options.torque_scale and subtracts
/// options.torque_bias.
/// Throws dynid::Error naming the file for missing columns (and the fix), no time information,
/// both joint- and motor-side columns, or bad numbers (see read_csv); dynid::UsageError for a
/// torque scale that is not 1 or n finite non-zero numbers, and for a window that is outside the
/// run or keeps fewer than 2 rows (the message gives the run's extent). `report`, when given,
/// receives a note per choice and a warning per option without effect (--rate with a t column).
JointRecord read_joint_record(const std::string& path, const Model& model,
                              const RunFileOptions& options = {}, RunFileReport* report = nullptr);

/// Reads a reference trajectory (`t`, `q*`, optional `dq*`, `ddq*`, e.g. from dynid excite) into
/// a record with an empty tau; missing derivatives are central differences on the time stamps.
/// Throws dynid::Error naming the file for a missing `t` or q columns.
JointRecord read_reference(const std::string& path, const Model& model,
                           const RunFileOptions& options = {});

}  // namespace dynid
