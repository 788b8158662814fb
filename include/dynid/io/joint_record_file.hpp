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

/// True when `--columns` names columns by position only (every `from` a positive integer);
/// throws dynid::UsageError when positions and names are mixed.
bool columns_by_position(const ColumnMapping& mapping);

/// Reads a run into a joint-side record: time from `t` (or `rate_hz`), positions from `q*`
/// (joint side) or `qm*` (motor side, converted with the model's transmission,
/// q = N⁻¹·qm + q_offset), torques from `tau*` or `taum*` (tau = Nᵀ·taum), and `dq*`, `ddq*` when
/// present (used as given). Columns `q<j>` or `q_<joint name>`; other columns ignored.
/// Then keeps options.window and scales the torques by options.torque_scale.
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
