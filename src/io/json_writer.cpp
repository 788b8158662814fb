#include "dynid/io/json_writer.hpp"

#include <cmath>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/atomic_file.hpp"

namespace dynid {
namespace {

// Path of the first non-finite number in `value` ("parameters[3].value"), or "" when all are
// finite. nlohmann would write NaN and Inf as null without a word.
std::string first_non_finite(const nlohmann::json& value, const std::string& path) {
  if (value.is_number_float()) return std::isfinite(value.get<double>()) ? "" : path;
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) {
      const std::string found = first_non_finite(item, path.empty() ? key : path + "." + key);
      if (!found.empty()) return found;
    }
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      const std::string found = first_non_finite(value[i], path + "[" + std::to_string(i) + "]");
      if (!found.empty()) return found;
    }
  }
  return "";
}

}  // namespace

void write_json(const std::string& path, const nlohmann::json& value, int indent) {
  const std::string bad = first_non_finite(value, "");
  if (!bad.empty()) {
    throw Error(path + ": refusing to write the non-finite value of '" + bad +
                "' (nothing was written); an input gave a result that overflowed, check its "
                "units and values");
  }
  // Names and paths come from the input and may not be valid UTF-8: replace such bytes by U+FFFD
  // instead of failing after all the work.
  const std::string text =
      value.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace) + '\n';
  write_text_atomic(path, text);
}

nlohmann::json json_number(double value) {
  if (!std::isfinite(value)) return nullptr;
  return value;
}

}  // namespace dynid
