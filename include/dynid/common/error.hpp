#pragma once

#include <stdexcept>
#include <string>

namespace dynid {

/// The one exception type dynid throws for bad input. Its message is a single line that names the
/// input at fault and says how to fix it; the CLI prints it as `error: <message>`.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

/// A usage error (bad flag combination, missing required option). The CLI exits with code 2.
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& message) : Error(message) {}
};

}  // namespace dynid
