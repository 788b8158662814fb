#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace dynid {

/// Writes `value` as JSON text (indented by `indent`, trailing newline) to `path` atomically
/// (atomic_file.hpp). Non-finite numbers must be stored as null by the caller (JSON has no
/// Inf/NaN); use json_number(). Throws dynid::Error when the file cannot be written.
void write_json(const std::string& path, const nlohmann::json& value, int indent = 2);

/// `value` as a JSON number, or null when it is NaN or infinite.
nlohmann::json json_number(double value);

}  // namespace dynid
