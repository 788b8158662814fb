#include "dynid/io/csv_writer.hpp"

#include <charconv>
#include <cmath>

#include "dynid/common/error.hpp"
#include "dynid/io/atomic_file.hpp"

namespace dynid {
namespace {

void check_columns(const std::vector<std::string>& columns, Eigen::Index cols) {
  if (static_cast<Eigen::Index>(columns.size()) != cols) {
    throw Error("CSV writer: " + std::to_string(columns.size()) + " column names for " +
                std::to_string(cols) + " data columns; pass one name per column");
  }
  for (const auto& c : columns) {
    if (c.empty() || c.find_first_of(",\"\r\n") != std::string::npos) {
      throw Error("CSV writer: column name '" + c +
                  "' is empty or contains a comma, quote or newline; use a plain name");
    }
  }
}

// The final guard of "no NaN or Inf leaves dynid": checked before the file is opened, so a refusal
// leaves nothing behind. The producer should have named the input at fault already.
void check_finite(const std::vector<std::string>& columns,
                  const Eigen::Ref<const Eigen::MatrixXd>& data, const std::string& path) {
  for (Eigen::Index i = 0; i < data.rows(); ++i) {
    for (Eigen::Index c = 0; c < data.cols(); ++c) {
      if (!std::isfinite(data(i, c))) {
        throw Error(path + ": refusing to write the non-finite value of " +
                    columns[static_cast<std::size_t>(c)] + " in data row " + std::to_string(i + 1) +
                    " (nothing was written); an input gave a result that overflowed, check its "
                    "units and values");
      }
    }
  }
}

std::string header_line(const std::vector<std::string>& columns) {
  std::string s;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (c) s += ',';
    s += columns[c];
  }
  s += '\n';
  return s;
}

void append_row(std::string& out, const Eigen::Ref<const Eigen::MatrixXd>& data, Eigen::Index i) {
  for (Eigen::Index c = 0; c < data.cols(); ++c) {
    if (c) out += ',';
    append_number(out, data(i, c));
  }
  out += '\n';
}

}  // namespace

void append_number(std::string& out, double value) {
  if (std::isnan(value)) {
    out += "nan";
    return;
  }
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out.append(buffer, result.ptr);
}

std::string format_csv(const std::vector<std::string>& columns,
                       const Eigen::Ref<const Eigen::MatrixXd>& data) {
  check_columns(columns, data.cols());
  check_finite(columns, data, "CSV text");
  std::string out = header_line(columns);
  for (Eigen::Index i = 0; i < data.rows(); ++i) append_row(out, data, i);
  return out;
}

void write_csv(const std::string& path, const std::vector<std::string>& columns,
               const Eigen::Ref<const Eigen::MatrixXd>& data) {
  check_columns(columns, data.cols());
  check_finite(columns, data, path);
  write_file_atomic(path, [&](std::ostream& out) {
    std::string buffer = header_line(columns);
    buffer.reserve(1 << 16);
    for (Eigen::Index i = 0; i < data.rows(); ++i) {
      append_row(buffer, data, i);
      if (buffer.size() > (1 << 16) - 1024) {
        out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        buffer.clear();
      }
    }
    out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  });
}

}  // namespace dynid
