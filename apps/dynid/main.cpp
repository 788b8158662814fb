// dynid command-line tool: see docs/cli.md. Exit codes: 0 success, 2 usage error (bad flags),
// 1 any other error. The error contract ("Exit codes and errors" in docs/cli.md) is enforced here
// and only here: every failure, whatever threw it, leaves as one line on stderr that starts with
// "error:", with library tags, control characters and invalid UTF-8 removed or escaped.

#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <string_view>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/version.hpp"

namespace {

int fail(int code, std::string_view message) {
  std::string line = dynid::one_line(message);
  if (line.empty()) line = "unexpected failure; please report it with the command line used";
  std::cerr << "error: " << line << '\n';
  return code;
}

// "dynid foo": CLI11 would say only that an argument was not expected.
std::string unknown_command(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return {};
  const std::string word = argv[1];
  std::string names;
  for (const CLI::App* sub : app.get_subcommands({})) {
    if (sub->get_name() == word) return {};
    names += (names.empty() ? "" : ", ") + sub->get_name();
  }
  return "unknown command '" + word + "'; commands are " + names +
         " (run 'dynid --help' for a summary)";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dynid: identification of robot dynamic parameters (see docs/cli.md)", "dynid"};
  app.set_version_flag(
      "--version", std::string("dynid ") + dynid::kVersion + " (commit " + dynid::kGitCommit + ")",
      "Print the version and the git commit it was built from, and exit");
  app.require_subcommand(1, 1);
  app.fallthrough(false);
  dynid::cli::add_commands(app);
  try {
    if (const std::string unknown = unknown_command(app, argc, argv); !unknown.empty()) {
      return fail(2, unknown);
    }
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    return fail(2, std::string(e.what()) + "; run 'dynid --help' or 'dynid <command> --help'");
  } catch (const dynid::UsageError& e) {
    return fail(2, e.what());
  } catch (const dynid::Error& e) {
    return fail(1, e.what());
  } catch (const std::bad_alloc&) {
    return fail(1,
                "out of memory; the input is too large for this machine (split the run or use "
                "a machine with more memory)");
  } catch (const std::exception& e) {
    return fail(1, e.what());
  } catch (...) {
    return fail(1, "");
  }
  return 0;
}
