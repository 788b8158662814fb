#pragma once

// Private helper of the model loaders (not installed).

#include <string>

namespace dynid::model_detail {

/// `text` made safe for a one-line error message: ASCII control characters become \n, \t, \r or
/// \xHH, bytes that are not part of valid UTF-8 become \xHH, and the result is cut to `max_chars`
/// bytes (at a character boundary) with "..." appended.
inline std::string printable(const std::string& text, std::size_t max_chars = 200) {
  static const char* kHex = "0123456789abcdef";
  std::string out;
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  for (std::size_t i = 0; i < n;) {
    if (out.size() >= max_chars) {
      out += "...";
      break;
    }
    const unsigned char c = s[i];
    std::size_t len = 0;  // length of a valid multi-byte UTF-8 sequence at i
    if (c >= 0xC2 && c <= 0xDF) len = 2;
    if (c >= 0xE0 && c <= 0xEF) len = 3;
    if (c >= 0xF0 && c <= 0xF4) len = 4;
    bool valid = len > 0 && i + len <= n;
    for (std::size_t k = 1; valid && k < len; ++k) valid = (s[i + k] & 0xC0) == 0x80;
    // Overlong 3-byte forms, UTF-16 surrogates and code points above U+10FFFF.
    if (valid && len == 3 && ((c == 0xE0 && s[i + 1] < 0xA0) || (c == 0xED && s[i + 1] >= 0xA0)))
      valid = false;
    if (valid && len == 4 && ((c == 0xF0 && s[i + 1] < 0x90) || (c == 0xF4 && s[i + 1] >= 0x90)))
      valid = false;
    if (valid) {
      out.append(text, i, len);
      i += len;
      continue;
    }
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c < 0x20 || c >= 0x7F) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 0xF];
    } else {
      out += static_cast<char>(c);
    }
    ++i;
  }
  // urdfdom and yaml-cpp end some messages with a newline or spaces.
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

}  // namespace dynid::model_detail
