#pragma once

// Private helpers shared by the in-memory and the streaming CSV readers (not installed).

#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid::csv_detail {

/// Length of a UTF-8 byte-order mark at the start of [b, e), else 0.
inline std::size_t bom_length(const char* b, const char* e) {
  return (e - b >= 3 && b[0] == '\xEF' && b[1] == '\xBB' && b[2] == '\xBF') ? 3 : 0;
}

/// The line terminator of a text whose start is [b, e): '\r' when its first line end is a CR not
/// followed by LF (classic Mac files), else '\n' (LF and CRLF files).
char detect_eol(const char* b, const char* e);

/// Throws the error for a line longer than kMaxCsvLineBytes; `line` is 1-based.
[[noreturn]] void throw_long_line(const std::string& source, long line);

/// Removes a trailing '\r' (CRLF files) from [b, e).
inline const char* strip_cr(const char* b, const char* e) {
  return (e > b && e[-1] == '\r') ? e - 1 : e;
}

/// True for a blank line or a `#` comment line.
bool is_skippable(const char* b, const char* e);

/// Splits and validates a header line (names trimmed, optional double quotes removed). Throws
/// dynid::Error for a numeric first line (no header), empty names and duplicates.
std::vector<std::string> parse_header(const char* b, const char* e, const std::string& source,
                                      long line);

/// Parses one data line (1-based data row `row`, for messages) into out[0], out[stride], ...
/// (columns.size() values). `unterminated` is true for a last line without a newline: any defect is
/// then reported as a truncated last line. Throws dynid::Error naming source, line, column and the
/// fix.
void parse_row(const char* b, const char* e, const std::vector<std::string>& columns, double* out,
               Eigen::Index stride, const std::string& source, long line, long row,
               bool unterminated);

/// Error for a file with no header line.
[[noreturn]] void throw_empty(const std::string& source);

}  // namespace dynid::csv_detail
