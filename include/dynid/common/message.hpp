#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace dynid {

/// Makes a message fit dynid's one-line contract (docs/cli.md "Exit codes and errors"): drops the
/// bracketed tags third-party libraries prefix (`[json.exception.type_error.302] `), escapes
/// control characters (`\n`, `\t`, `\xNN`) and bytes that are not valid UTF-8 (`\xNN`), and trims
/// surrounding blanks. Valid multi-byte UTF-8 (N·m, names in any script) is kept. The result is
/// one line of valid UTF-8 with no control characters; it is empty only when `text` is blank.
std::string one_line(std::string_view text);

/// Input text (a name, a value, a library's reason) made safe to quote in a one-line message: as
/// one_line() but without dropping tags, cut after `max_bytes` at a character boundary with "..."
/// appended, so that a long or binary input cannot flood the message.
std::string printable(std::string_view text, std::size_t max_bytes = 200);

/// `x` in 4 significant digits for messages ("1.6e+07", "0.2", "inf"), so that a value from the
/// input never floods a message with hundreds of digits as std::to_string(1e300) would.
std::string short_number(double x);

/// `text` with every byte sequence that is not valid UTF-8 replaced by U+FFFD, for names that
/// come from the input and are written into JSON (JSON text must be UTF-8).
std::string valid_utf8(std::string_view text);

}  // namespace dynid
