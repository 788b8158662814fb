#pragma once

// Runs the built dynid binary (compile definition DYNID_BINARY) for the CLI tests.

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace dynid::testing {

/// Exit code, stdout and stderr of one dynid run.
struct CliResult {
  int code = -1;
  std::string out;
  std::string err;
};

/// The whole content of a file ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `dynid <args>` (shell words; paths without spaces) with stdin from /dev/null; stdout and
/// stderr go through files in `scratch`, which must exist.
inline CliResult run_dynid(const std::string& args, const std::filesystem::path& scratch) {
  const std::filesystem::path out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string command = std::string("'") + DYNID_BINARY + "' " + args + " >'" + out.string() +
                              "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(command.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

}  // namespace dynid::testing
