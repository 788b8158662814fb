#include "dynid/io/csv_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include <sys/stat.h>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "io/csv_parse.hpp"

namespace dynid {
namespace {

// Whole file, read with a cap (kMaxCsvFileBytes) and a line-length check as it arrives, so that
// a device or pipe without line ends (/dev/zero) ends in an error after one line's worth of bytes.
std::string read_whole_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) {
    throw Error(path + ": is a directory; give the path of a CSV file to --in");
  }
  require_regular_file(path, "CSV file");
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"),
                                                       &std::fclose);
  if (!file) {
    throw Error(path + ": cannot open (" + std::strerror(errno) +
                "); check the path given to --in");
  }
  auto too_large = [&]() {
    throw Error(path + ": larger than " + std::to_string(kMaxCsvFileBytes >> 20) +
                " MiB, the limit for reading a CSV file into memory; use --stream where the "
                "command offers it, or split the file");
  };
  std::string text;
  if (S_ISREG(st.st_mode)) {
    if (static_cast<std::size_t>(st.st_size) > kMaxCsvFileBytes) too_large();
    text.reserve(static_cast<std::size_t>(st.st_size));
  }
  std::size_t line_start = 0;  // offset just after the last line end seen
  char buffer[1 << 16];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof(buffer), file.get())) > 0) {
    if (text.size() + got > kMaxCsvFileBytes) too_large();
    const std::size_t before = text.size();
    text.append(buffer, got);
    const void* lf = ::memrchr(text.data() + before, '\n', got);
    const void* cr = ::memrchr(text.data() + before, '\r', got);
    const char* last = std::max(static_cast<const char*>(lf), static_cast<const char*>(cr));
    if (last != nullptr) line_start = static_cast<std::size_t>(last - text.data()) + 1;
    if (text.size() - line_start > kMaxCsvLineBytes) {
      const long line = 1 + static_cast<long>(std::count(text.begin(), text.end(), '\n'));
      csv_detail::throw_long_line(path, line);
    }
  }
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
  const char* const end = text.data() + text.size();
  const char* p = text.data() + bom_length(text.data(), end);
  const char eol = detect_eol(p, end);
  long line = 0;
  // Next line as [b, e) without its CR/LF; false at the end of the text.
  const char* b = nullptr;
  const char* e = nullptr;
  bool terminated = true;
  auto next_line = [&]() {
    if (p >= end) return false;
    const char* nl =
        static_cast<const char*>(std::memchr(p, eol, static_cast<std::size_t>(end - p)));
    b = p;
    terminated = nl != nullptr;
    if (static_cast<std::size_t>((terminated ? nl : end) - b) > kMaxCsvLineBytes)
      throw_long_line(source, line + 1);
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
        static_cast<const char*>(std::memchr(q, eol, static_cast<std::size_t>(end - q)));
    ++capacity;
    if (nl == nullptr) break;
    q = nl + 1;
  }
  if (capacity > kMaxCsvRows + 1) {
    throw Error(source + ": more than " + std::to_string(kMaxCsvRows) +
                " lines, the limit for reading a CSV file into memory; use --stream where the "
                "command offers it, or split the file");
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
