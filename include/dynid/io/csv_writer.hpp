#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// Appends `value` to `out` in the shortest decimal form that parses back to the same double
/// (std::to_chars), so that write_csv -> read_csv is exact. NaN/Inf are written as nan/inf.
void append_number(std::string& out, double value);

/// CSV text: header line `columns` joined by commas, then one line per row of `data` (LF ends).
/// Throws dynid::Error if columns.size() != data.cols(), a column name contains a comma,
/// quote, newline or is empty, or a value is NaN or infinite (naming its column and row).
std::string format_csv(const std::vector<std::string>& columns,
                       const Eigen::Ref<const Eigen::MatrixXd>& data);

/// Writes format_csv(columns, data) to `path` atomically (atomic_file.hpp), streaming in blocks.
/// Throws dynid::Error as format_csv and write_file_atomic.
void write_csv(const std::string& path, const std::vector<std::string>& columns,
               const Eigen::Ref<const Eigen::MatrixXd>& data);

}  // namespace dynid
