#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "dynid/io/csv_table.hpp"

namespace dynid {

/// Input size limits of the CSV readers (docs/cli.md, "Input size limits"). Beyond them the readers
/// throw dynid::Error instead of exhausting memory.
inline constexpr std::size_t kMaxCsvLineBytes = std::size_t{1} << 20;    ///< one line, both readers
inline constexpr std::size_t kMaxCsvColumns = 65536;                     ///< header fields
inline constexpr std::size_t kMaxCsvFileBytes = std::size_t{256} << 20;  ///< read_csv only
inline constexpr long kMaxCsvRows = 20'000'000;                          ///< read_csv only

/// Reads a whole CSV file (docs/design.md section 4) into memory.
/// Format: first non-comment, non-blank line is the header (names, optionally double-quoted); then
/// one row of numbers per line, comma separated; lines whose first non-blank character is `#` are
/// comments; LF, CRLF or CR-only line ends (the first line end decides); a leading UTF-8 byte-order
/// mark is skipped; blank lines are skipped; spaces/tabs around fields are ignored.
/// Numbers are parsed with fast_float (exact round trip of shortest/%.17g output).
/// Throws dynid::Error (one line naming file, line and column, and the fix) for: missing or
/// unreadable file, empty file, numeric first line (no header), empty or duplicate column names,
/// ragged rows, non-numeric fields, NaN/Inf values, and a truncated last line (no final newline and
/// too few fields or a partial number), and input beyond the limits above (the file is read with a
/// cap, so devices and pipes such as /dev/zero end in an error).
CsvTable read_csv(const std::string& path);

/// Same as read_csv on text already in memory; `source` names it in error messages.
CsvTable parse_csv(std::string_view text, const std::string& source);

/// read_csv for a file without a header row (raw logs): the columns are named by their 1-based
/// position "1", "2", …, as many as the first data line has fields. Throws as read_csv, and
/// dynid::Error when the first line is not numbers (the file has a header: name its columns).
CsvTable read_csv_without_header(const std::string& path);

}  // namespace dynid
