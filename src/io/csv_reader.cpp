#include "dynid/io/csv_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "dynid/common/error.hpp"
#include "io/csv_parse.hpp"

namespace dynid {
namespace {

std::string read_whole_file(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) {
    throw Error(path + ": cannot open (" + std::strerror(errno) +
                "); check the path given to --in");
  }
  std::string text;
  if (std::fseek(file.get(), 0, SEEK_END) == 0) {
    const long size = std::ftell(file.get());
    std::rewind(file.get());
    if (size > 0) {  // regular file: one read into place
      text.resize(static_cast<std::size_t>(size));
      text.resize(std::fread(text.data(), 1, text.size(), file.get()));
    }
  }
  char buffer[1 << 16];  // anything left (pipes, files that grew)
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof(buffer), file.get())) > 0) text.append(buffer, got);
  if (std::ferror(file.get())) {
    throw Error(path + ": read error (" + std::strerror(errno) + "); check the file");
  }
  return text;
}

CsvTable parse_csv_text(std::string_view text, const std::string& source, bool header);

}  // namespace

CsvTable read_csv(const std::string& path) {
  return parse_csv_text(read_whole_file(path), path, true);
}

CsvTable read_csv_without_header(const std::string& path) {
  return parse_csv_text(read_whole_file(path), path, false);
}

CsvTable parse_csv(std::string_view text, const std::string& source) {
  return parse_csv_text(text, source, true);
}

namespace {

CsvTable parse_csv_text(std::string_view text, const std::string& source, bool header) {
  using namespace csv_detail;
  CsvTable table;
  table.source = source;
  const char* p = text.data();
  const char* const end = p + text.size();
  long line = 0;
  // Next line as [b, e) without its CR/LF; false at the end of the text.
  const char* b = nullptr;
  const char* e = nullptr;
  bool terminated = true;
  auto next_line = [&]() {
    if (p >= end) return false;
    const char* nl =
        static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end - p)));
    b = p;
    terminated = nl != nullptr;
    e = strip_cr(b, terminated ? nl : end);
    p = terminated ? nl + 1 : end;
    ++line;
    return true;
  };

  bool have_header = false;
  const char* const before_first = p;
  const long line_before_first = line;
  while (next_line()) {
    if (is_skippable(b, e)) continue;
    if (header) {
      table.columns = parse_header(b, e, source, line);
    } else {
      // Columns named by position; the first line is read again below as data.
      const auto fields = std::count(b, e, ',') + 1;
      for (long c = 1; c <= fields; ++c) table.columns.push_back(std::to_string(c));
      p = before_first;
      line = line_before_first;
    }
    have_header = true;
    break;
  }
  if (!have_header) throw_empty(source);
  const auto n = static_cast<Eigen::Index>(table.columns.size());

  // Upper bound on the data rows: the remaining line count.
  Eigen::Index capacity = 1;
  for (const char* q = p; q < end;) {
    const char* nl =
        static_cast<const char*>(std::memchr(q, '\n', static_cast<std::size_t>(end - q)));
    ++capacity;
    if (nl == nullptr) break;
    q = nl + 1;
  }
  // Rows are parsed into contiguous row-major storage (sequential writes), then transposed once.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> buffer(capacity, n);
  table.lines.reserve(static_cast<std::size_t>(capacity));
  Eigen::Index rows = 0;
  while (next_line()) {
    if (is_skippable(b, e)) continue;
    if (!header && rows == 0) {
      try {
        parse_row(b, e, table.columns, buffer.data(), 1, source, line, 1, !terminated);
      } catch (const Error& ex) {
        throw Error(std::string(ex.what()) +
                    " (the file was read without a header because --columns names columns by "
                    "position; if its first line is a header, name those columns instead)");
      }
    } else {
      parse_row(b, e, table.columns, buffer.data() + rows * n, 1, source, line,
                static_cast<long>(rows) + 1, !terminated);
    }
    table.lines.push_back(line);
    ++rows;
  }
  if (rows == 0) {
    throw Error(source + ": header but no data rows; add one line of numbers per sample");
  }
  table.data = buffer.topRows(rows);
  return table;
}

}  // namespace
}  // namespace dynid
