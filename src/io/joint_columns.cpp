#include "dynid/io/joint_columns.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <set>

#include "dynid/common/error.hpp"

namespace dynid {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::string join(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

/// k if `name` is `<prefix><k>` with k a positive decimal integer, else 0.
int numbered_index(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return 0;
  int k = 0;
  for (std::size_t i = prefix.size(); i < name.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(name[i])) || k > 100000) return 0;
    k = 10 * k + (name[i] - '0');
  }
  return name[prefix.size()] == '0' ? 0 : k;
}

}  // namespace

ColumnMapping parse_column_mapping(const std::string& text) {
  ColumnMapping mapping;
  std::set<std::string> from_seen;
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    const std::string item =
        trim(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    start = comma == std::string::npos ? text.size() + 1 : comma + 1;
    if (item.empty()) continue;
    const auto eq = item.find('=');
    const std::string from = eq == std::string::npos ? "" : trim(item.substr(0, eq));
    const std::string to = eq == std::string::npos ? "" : trim(item.substr(eq + 1));
    if (from.empty() || to.empty()) {
      throw UsageError("--columns entry '" + item +
                       "' is not from=to; write e.g. --columns pos1=q1,pos2=q2");
    }
    if (!from_seen.insert(from).second) {
      throw UsageError("--columns maps '" + from + "' twice; give each column one new name");
    }
    mapping.emplace_back(from, to);
  }
  return mapping;
}

void apply_column_mapping(CsvTable& table, const ColumnMapping& mapping) {
  std::vector<std::string> renamed = table.columns;
  for (const auto& [from, to] : mapping) {
    const auto c = table.find(from);
    if (!c) {
      throw Error(table.source + ": --columns names '" + from + "', which is not in the header (" +
                  join(table.columns) + "); use a column name from the header");
    }
    renamed[static_cast<std::size_t>(*c)] = to;
  }
  std::set<std::string> seen;
  for (const auto& name : renamed) {
    if (!seen.insert(name).second) {
      throw Error(table.source + ": after --columns the header has column '" + name +
                  "' twice; rename it to a name not already in the file");
    }
  }
  table.columns = std::move(renamed);
}

bool has_joint_columns(const std::vector<std::string>& columns,
                       const std::vector<std::string>& joint_names, const std::string& prefix) {
  for (std::size_t j = 0; j < joint_names.size(); ++j) {
    const std::string numbered = prefix + std::to_string(j + 1);
    const std::string named = prefix + "_" + joint_names[j];
    for (const auto& c : columns) {
      if (c == numbered || c == named) return true;
    }
  }
  return false;
}

std::vector<std::string> joints_named_in_columns(const std::vector<std::string>& columns,
                                                 const std::vector<std::string>& joint_names) {
  const std::set<std::string> known(joint_names.begin(), joint_names.end());
  std::vector<std::string> named;
  std::set<std::string> seen;
  for (const std::string& c : columns) {
    for (const char* prefix : {"q_", "qm_"}) {
      const std::string p(prefix);
      if (c.size() <= p.size() || c.compare(0, p.size(), p) != 0) continue;
      const std::string name = c.substr(p.size());
      if (known.count(name) && seen.insert(name).second) named.push_back(name);
    }
  }
  return named;
}

std::vector<Eigen::Index> resolve_joint_columns(const std::vector<std::string>& columns,
                                                const std::vector<std::string>& joint_names,
                                                const std::string& prefix,
                                                const std::string& source) {
  const int n = static_cast<int>(joint_names.size());
  // Joint count implied by the numbered columns <prefix>1..<prefix>k.
  std::vector<int> numbered;
  for (const auto& c : columns) {
    if (const int k = numbered_index(c, prefix)) numbered.push_back(k);
  }
  std::sort(numbered.begin(), numbered.end());
  if (!numbered.empty() && numbered.back() > n) {
    throw Error(source + ": has columns " + prefix + "1.." + prefix +
                std::to_string(numbered.back()) + " but the model has " + std::to_string(n) +
                " joints; use a data file recorded on this robot (or --robot matching the data)");
  }
  std::vector<Eigen::Index> index(static_cast<std::size_t>(n), -1);
  std::vector<std::string> missing;
  for (int j = 0; j < n; ++j) {
    const std::string a = prefix + std::to_string(j + 1);
    const std::string b = prefix + "_" + joint_names[static_cast<std::size_t>(j)];
    Eigen::Index ia = -1;
    Eigen::Index ib = -1;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (columns[c] == a) ia = static_cast<Eigen::Index>(c);
      if (columns[c] == b) ib = static_cast<Eigen::Index>(c);
    }
    if (ia >= 0 && ib >= 0) {
      throw Error(source + ": joint " + std::to_string(j + 1) + " has both columns '" + a +
                  "' and '" + b + "'; keep one of them");
    }
    index[static_cast<std::size_t>(j)] = ia >= 0 ? ia : ib;
    if (index[static_cast<std::size_t>(j)] < 0) missing.push_back(a);
  }
  if (missing.empty()) return index;
  std::string count_note;
  if (!numbered.empty() && numbered.back() == static_cast<int>(numbered.size())) {
    const auto k = numbered.size();
    count_note = "; the file has columns " + prefix + "1.." + prefix + std::to_string(k) + " (" +
                 std::to_string(k) + (k == 1 ? " joint" : " joints") + ") but the model has " +
                 std::to_string(n) + " joints";
  }
  throw Error(source + ": missing column" + (missing.size() > 1 ? "s " : " ") + join(missing) +
              " (or " + prefix + "_<joint name>)" + count_note +
              "; available columns: " + join(columns) +
              "; use data recorded on this robot or rename columns with --columns from=to");
}

Eigen::MatrixXd joint_signal(const CsvTable& table, const std::vector<std::string>& joint_names,
                             const std::string& prefix) {
  const auto index = resolve_joint_columns(table.columns, joint_names, prefix, table.source);
  Eigen::MatrixXd out(table.rows(), static_cast<Eigen::Index>(index.size()));
  for (std::size_t j = 0; j < index.size(); ++j) {
    out.col(static_cast<Eigen::Index>(j)) = table.data.col(index[j]);
  }
  return out;
}

std::optional<Eigen::Index> checked_time_column(const CsvTable& table) {
  const auto c = table.find("t");
  if (!c) return std::nullopt;
  for (Eigen::Index i = 1; i < table.rows(); ++i) {
    if (!(table.data(i, *c) > table.data(i - 1, *c))) {
      char buffer[160];
      std::snprintf(buffer, sizeof(buffer), "time t = %.17g is not greater than %.17g on line %ld",
                    table.data(i, *c), table.data(i - 1, *c), table.line_of(i - 1));
      throw Error(table.source + ":" + std::to_string(table.line_of(i)) + ": " + buffer +
                  "; time must be strictly increasing: sort the rows or remove duplicates");
    }
  }
  return c;
}

}  // namespace dynid
