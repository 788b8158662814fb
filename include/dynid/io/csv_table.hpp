#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid {

/// A numeric CSV file in memory (docs/design.md section 4): one named column per signal, one row
/// per sample. data(i, c) is sample i of column columns[c].
struct CsvTable {
  std::string source;                ///< file the table was read from (for error messages)
  std::vector<std::string> columns;  ///< header names, unique, in file order
  Eigen::MatrixXd data;              ///< rows = samples, cols = columns.size()
  std::vector<long> lines;           ///< 1-based file line of each row (empty if built by hand)

  Eigen::Index rows() const { return data.rows(); }

  /// Index of the column named `name`, or std::nullopt.
  std::optional<Eigen::Index> find(const std::string& name) const;

  /// Index of the column named `name`. Throws dynid::Error naming the file, the missing column and
  /// the available header.
  Eigen::Index index(const std::string& name) const;

  /// File line of row i for messages (i + 2 when `lines` is empty: header on line 1).
  long line_of(Eigen::Index row) const;
};

}  // namespace dynid
