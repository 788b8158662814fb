#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace dynid {

/// Writes `value` as JSON text (indented by `indent`, trailing newline) to `path` atomically
/// (atomic_file.hpp). Bytes that are not valid UTF-8 in strings (names from the input) are
/// replaced by U+FFFD. JSON has no Inf/NaN: a quantity that may legitimately be undefined is stored
/// as null by the caller (json_number()); any other non-finite number makes this throw
/// dynid::Error naming its key, before anything is written. Also throws dynid::Error when the file
/// cannot be written.
void write_json(const std::string& path, const nlohmann::json& value, int indent = 2);

/// `value` as a JSON number, or null when it is NaN or infinite.
nlohmann::json json_number(double value);

}  // namespace dynid
