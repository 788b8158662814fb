#pragma once

// Runs the built dynid binary (compile definition DYNID_BINARY) for the CLI tests.

#include <sys/wait.h>
#include <unistd.h>

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
/// stderr go through files in `scratch`, which must exist, named after this process: ctest runs
/// test cases as parallel processes, which share a scratch folder.
inline CliResult run_dynid(const std::string& args, const std::filesystem::path& scratch) {
  const std::string pid = std::to_string(::getpid());
  const std::filesystem::path out = scratch / ("stdout." + pid + ".txt"),
                              err = scratch / ("stderr." + pid + ".txt");
  const std::string command = std::string("'") + DYNID_BINARY + "' " + args + " >'" + out.string() +
                              "' 2>'" + err.string() + "' </dev/null";
  const int status = std::system(command.c_str());
  CliResult r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// What breaks the error contract of docs/cli.md in the stderr of a failed run, or "" when it
/// holds: the last line is the one line that starts with "error: "; the lines before it may only be
/// the command's echo of its choices ("identify: …") and warnings ("warning: …"); no line has a
/// control character.
inline std::string error_contract_problem(const std::string& err) {
  if (err.empty() || err.back() != '\n') return "stderr does not end with a line end";
  std::istringstream lines(err);
  std::string line, last;
  int errors = 0;
  while (std::getline(lines, line)) {
    for (const char ch : line) {
      const auto c = static_cast<unsigned char>(ch);
      if (c < 0x20 || c == 0x7F) return "control character in stderr line: " + line;
    }
    if (line.rfind("error: ", 0) == 0) {
      ++errors;
    } else if (line.rfind("warning: ", 0) != 0 && line.find(": ") == std::string::npos) {
      return "stderr line is neither an echo, a warning nor the error: " + line;
    }
    last = line;
  }
  if (errors != 1) return "stderr has " + std::to_string(errors) + " lines starting with 'error: '";
  if (last.rfind("error: ", 0) != 0) return "the error is not the last line of stderr";
  return {};
}

}  // namespace dynid::testing
