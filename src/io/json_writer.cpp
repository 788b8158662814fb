#include "dynid/io/json_writer.hpp"

#include <cmath>

#include "dynid/io/atomic_file.hpp"

namespace dynid {

void write_json(const std::string& path, const nlohmann::json& value, int indent) {
  write_file_atomic(path, [&](std::ostream& out) { out << value.dump(indent) << '\n'; });
}

nlohmann::json json_number(double value) {
  if (!std::isfinite(value)) return nullptr;
  return value;
}

}  // namespace dynid
