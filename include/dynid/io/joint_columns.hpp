#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "dynid/io/csv_table.hpp"

namespace dynid {

/// User renaming of CSV columns, applied before lookup: pairs (from, to).
using ColumnMapping = std::vector<std::pair<std::string, std::string>>;

/// Parses `--columns` text "from=to,from2=to2" (spaces around names ignored; empty text gives an
/// empty mapping). Throws dynid::UsageError for an entry without '=' or with an empty side, and
/// for a name mapped twice.
ColumnMapping parse_column_mapping(const std::string& text);

/// Renames table columns per `mapping` (from -> to). Throws dynid::Error naming the file when a
/// `from` column is absent (lists the header) or the renaming creates duplicate names.
void apply_column_mapping(CsvTable& table, const ColumnMapping& mapping);

/// Finds the column of each joint signal `prefix` (q, dq, ddq, tau, qr, qm, taum ...) for joints in
/// model order: `<prefix><j>` (j = 1..n) or `<prefix>_<joint name>`; any column order, other
/// columns ignored. Returns n column indices into `columns`.
/// Throws dynid::Error (`source` names the file) when: the file's `<prefix><k>` columns imply a
/// different joint count (e.g. q1..q5 for a 6-DoF model), a joint has both forms, or columns are
/// missing (names the missing ones, lists the available header and suggests --columns).
std::vector<Eigen::Index> resolve_joint_columns(const std::vector<std::string>& columns,
                                                const std::vector<std::string>& joint_names,
                                                const std::string& prefix,
                                                const std::string& source);

/// True when at least one joint has a `prefix` column (either naming form).
bool has_joint_columns(const std::vector<std::string>& columns,
                       const std::vector<std::string>& joint_names, const std::string& prefix);

/// The joints of `joint_names` that the header names by a `q_<joint name>` or `qm_<joint name>`
/// column, in header order, each once; empty when it names none (issue 26 item 1: a log of some of
/// a robot file's joints is matched to it by name).
std::vector<std::string> joints_named_in_columns(const std::vector<std::string>& columns,
                                                 const std::vector<std::string>& joint_names);

/// The samples × n matrix of signal `prefix` in joint order (resolve_joint_columns on the table).
Eigen::MatrixXd joint_signal(const CsvTable& table, const std::vector<std::string>& joint_names,
                             const std::string& prefix);

/// Index of the time column `t`, if present, after checking that it is strictly increasing.
/// Throws dynid::Error naming the file line where t does not increase.
std::optional<Eigen::Index> checked_time_column(const CsvTable& table);

}  // namespace dynid
