#include "io/csv_parse.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <system_error>
#include <unordered_set>

#include <fast_float/fast_float.h>

#include "dynid/common/error.hpp"
#include "dynid/io/csv_reader.hpp"

namespace dynid::csv_detail {
namespace {

inline bool is_space(char c) {
  return c == ' ' || c == '\t';
}

const char* skip_spaces(const char* p, const char* e) {
  while (p < e && is_space(*p)) ++p;
  return p;
}

std::string where(const std::string& source, long line) {
  return source + ":" + std::to_string(line) + ": ";
}

/// Text of the field starting at p (up to the next comma), trimmed and shortened for messages.
std::string field_text(const char* p, const char* e) {
  const char* comma = std::find(p, e, ',');
  std::string s(p, comma);
  while (!s.empty() && is_space(s.back())) s.pop_back();
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

long count_fields(const char* b, const char* e) {
  return b == e ? 0 : 1 + static_cast<long>(std::count(b, e, ','));
}

/// Parses a number at p (optional leading '+'); returns the end or nullptr.
const char* parse_number(const char* p, const char* e, double& value) {
  const char* q = (p < e && *p == '+') ? p + 1 : p;
  if (q < e && (*q == '+' || *q == '-') && q != p) return nullptr;
  const auto result = fast_float::from_chars(q, e, value);
  if (result.ec != std::errc()) return nullptr;
  return result.ptr;
}

}  // namespace

char detect_eol(const char* b, const char* e) {
  for (const char* p = b; p < e; ++p) {
    if (*p == '\n') return '\n';
    if (*p == '\r') return (p + 1 < e && p[1] == '\n') ? '\n' : '\r';
  }
  return '\n';
}

void throw_long_line(const std::string& source, long line) {
  throw Error(where(source, line) + "line is longer than " +
              std::to_string(kMaxCsvLineBytes >> 20) +
              " MiB (the limit of one CSV line); check that the file is a CSV with one sample per "
              "line");
}

bool is_skippable(const char* b, const char* e) {
  const char* p = skip_spaces(b, e);
  return p == e || *p == '#';
}

void throw_empty(const std::string& source) {
  throw Error(source +
              ": file is empty (no header row); write a header line such as t,q1,q2 followed by "
              "one line of numbers per sample");
}

std::vector<std::string> parse_header(const char* b, const char* e, const std::string& source,
                                      long line) {
  std::vector<std::string> names;
  bool all_numeric = true;
  const char* p = b;
  while (true) {
    const char* comma = std::find(p, e, ',');
    const char* fb = skip_spaces(p, comma);
    const char* fe = comma;
    while (fe > fb && is_space(fe[-1])) --fe;
    double v = 0.0;
    const char* num_end = parse_number(fb, fe, v);
    if (num_end != fe || fb == fe) all_numeric = false;
    if (fe - fb >= 2 && *fb == '"' && fe[-1] == '"') {
      ++fb;
      --fe;
    }
    names.emplace_back(fb, fe);
    if (comma == e) break;
    p = comma + 1;
  }
  if (names.size() > kMaxCsvColumns) {
    throw Error(where(source, line) + "header has " + std::to_string(names.size()) +
                " columns, more than the limit of " + std::to_string(kMaxCsvColumns) +
                "; split the file");
  }
  if (all_numeric) {
    throw Error(where(source, line) +
                "first line is numbers, not a header; add a header row naming the columns (e.g. "
                "t,q1,q2,dq1,dq2)");
  }
  std::unordered_set<std::string> seen;
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (names[c].empty()) {
      throw Error(where(source, line) + "header field " + std::to_string(c + 1) +
                  " is empty; give every column a name (or remove the trailing comma)");
    }
    if (!seen.insert(names[c]).second) {
      throw Error(where(source, line) + "duplicate column name '" + names[c] +
                  "' in the header; rename or remove one of the two columns");
    }
  }
  return names;
}

void parse_row(const char* b, const char* e, const std::vector<std::string>& columns, double* out,
               Eigen::Index stride, const std::string& source, long line, long row,
               bool unterminated) {
  const std::size_t n = columns.size();
  auto truncated = [&]() {
    if (unterminated) {
      throw Error(where(source, line) + "truncated last line (" +
                  std::to_string(count_fields(b, e)) + " of " + std::to_string(n) +
                  " fields, no final newline); the file was cut off: regenerate it or delete the "
                  "partial last line");
    }
  };
  auto ragged = [&]() {
    truncated();
    throw Error(where(source, line) + "row has " + std::to_string(count_fields(b, e)) +
                " fields but the header has " + std::to_string(n) +
                "; give every row one value per column");
  };
  const char* p = b;
  std::size_t c = 0;
  const char* field = p;
  // Built once per row, not per field (its captures were stored on every iteration).
  auto not_a_number = [&]() {
    truncated();
    const std::string text = field_text(field, e);
    throw Error(
        where(source, line) + "column '" + columns[c] + "' (field " + std::to_string(c + 1) +
        "): " + (text.empty() ? std::string("empty field") : "'" + text + "' is not a number") +
        "; write one decimal number per field (e.g. 0.5 or -1.2e-3)");
  };
  for (; c < n; ++c) {
    p = skip_spaces(p, e);
    field = p;
    double v = 0.0;
    const char* end = parse_number(p, e, v);
    if (end == nullptr) {
      if (p == e && c + 1 < n) ragged();
      not_a_number();
    }
    p = skip_spaces(end, e);
    if (p != e && *p != ',') not_a_number();
    if (!std::isfinite(v)) {
      throw Error(where(source, line) + "column '" + columns[c] + "' (field " +
                  std::to_string(c + 1) + ") of data row " + std::to_string(row) + " is " +
                  (std::isnan(v) ? "NaN" : "infinite") +
                  "; remove or interpolate the sample before using the file");
    }
    out[static_cast<Eigen::Index>(c) * stride] = v;
    if (c + 1 < n) {
      if (p == e) ragged();
      ++p;  // the comma
    }
  }
  if (p != e) ragged();  // p is at a comma: too many fields
}

}  // namespace dynid::csv_detail
