#include "dynid/common/message.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace dynid {
namespace {

// Length of the valid UTF-8 sequence starting at text[i] (RFC 3629: no overlong forms, no
// surrogates, at most U+10FFFF), or 0 when the bytes there are not valid UTF-8.
std::size_t utf8_length(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  std::size_t len = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // allowed range of the second byte
  if (c >= 0xC2 && c <= 0xDF) {
    len = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    len = 3;
    if (c == 0xE0) lo = 0xA0;
    if (c == 0xED) hi = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    len = 4;
    if (c == 0xF0) lo = 0x90;
    if (c == 0xF4) hi = 0x8F;
  } else {
    return 0;
  }
  if (i + len > text.size()) return 0;
  if (byte(i + 1) < lo || byte(i + 1) > hi) return 0;
  for (std::size_t k = 2; k < len; ++k) {
    if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return 0;
  }
  return len;
}

void append_hex(std::string& out, unsigned char c) {
  char buffer[8];
  std::snprintf(buffer, sizeof(buffer), "\\x%02X", c);
  out += buffer;
}

// Removes "[json.exception.type_error.302] " style tags: a '[' whose bracketed text is a dotted
// identifier (letters, digits, '_' and '.', with at least one '.') followed by "] ".
std::string drop_library_tags(std::string_view text) {
  std::string out;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '[') {
      std::size_t k = i + 1;
      bool dotted = false;
      while (k < text.size() && (std::isalnum(static_cast<unsigned char>(text[k])) ||
                                 text[k] == '_' || text[k] == '.')) {
        dotted |= text[k] == '.';
        ++k;
      }
      if (dotted && k < text.size() && text[k] == ']') {
        i = k + 1;
        while (i < text.size() && text[i] == ' ') ++i;
        continue;
      }
    }
    out += text[i++];
  }
  return out;
}

// Escapes control characters (`\n`, `\r`, `\t`, `\xNN`, C1 controls too) and bytes that are
// not valid UTF-8 (`\xNN`); valid multi-byte UTF-8 is kept. Stops after `max_bytes` of output, at
// a character boundary, and appends "..." when it cut the text.
std::string escape(std::string_view plain, std::size_t max_bytes) {
  std::string out;
  out.reserve(std::min(plain.size(), max_bytes) + 4);
  for (std::size_t i = 0; i < plain.size();) {
    if (out.size() >= max_bytes) {
      out += "...";
      break;
    }
    const unsigned char c = static_cast<unsigned char>(plain[i]);
    const std::size_t len = utf8_length(plain, i);
    if (len == 0) {
      append_hex(out, c);
      ++i;
    } else if (c == '\n') {
      out += "\\n";
      ++i;
    } else if (c == '\r') {
      out += "\\r";
      ++i;
    } else if (c == '\t') {
      out += "\\t";
      ++i;
    } else if (c < 0x20 || c == 0x7F) {
      append_hex(out, c);
      ++i;
    } else if (len == 2 && c == 0xC2 && static_cast<unsigned char>(plain[i + 1]) < 0xA0) {
      append_hex(out, c);  // C1 control characters (U+0080–U+009F)
      append_hex(out, static_cast<unsigned char>(plain[i + 1]));
      i += 2;
    } else {
      out.append(plain, i, len);
      i += len;
    }
  }
  return out;
}

std::string trim_blanks(const std::string& text) {
  const auto first = text.find_first_not_of(' ');
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(' ') - first + 1);
}

}  // namespace

std::string one_line(std::string_view text) {
  return trim_blanks(escape(drop_library_tags(text), std::string::npos));
}

std::string printable(std::string_view text, std::size_t max_bytes) {
  return trim_blanks(escape(text, max_bytes));
}

std::string short_number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", x);
  return buffer;
}

std::string valid_utf8(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const std::size_t len = utf8_length(text, i);
    if (len == 0) {
      out += "\xEF\xBF\xBD";
      ++i;
    } else {
      out.append(text.substr(i, len));
      i += len;
    }
  }
  return out;
}

}  // namespace dynid
