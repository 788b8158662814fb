#include "dynid/io/csv_table.hpp"

#include "dynid/common/error.hpp"

namespace dynid {

std::optional<Eigen::Index> CsvTable::find(const std::string& name) const {
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c] == name) return static_cast<Eigen::Index>(c);
  }
  return std::nullopt;
}

Eigen::Index CsvTable::index(const std::string& name) const {
  if (auto c = find(name)) return *c;
  std::string header;
  for (const auto& c : columns) header += (header.empty() ? "" : ",") + c;
  throw Error(source + ": no column '" + name + "' (header: " + header +
              "); add the column or rename one with --columns from=to");
}

long CsvTable::line_of(Eigen::Index row) const {
  if (row >= 0 && static_cast<std::size_t>(row) < lines.size()) return lines[row];
  return static_cast<long>(row) + 2;
}

}  // namespace dynid
