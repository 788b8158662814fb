// libFuzzer harness for the CLI argument layer: the input is split at newlines into argv (after
// "dynid"), parsed by CLI11 with the real subcommand definitions (apps/dynid/cmd_*.cpp). The parse
// stops before the subcommand callbacks, so the harness covers flag parsing, type conversion and
// option checks, not the computations (those go through the built binary in
// tests/cli/cli_fuzz_test.cpp). Clean outcomes are the ones main.cpp maps to an exit code:
// success, --help/--version, CLI::ParseError and dynid::Error.

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "fuzz_support.hpp"

namespace {
/// Thrown by a subcommand's parse-complete callback: the command line parsed and validated.
struct ParseComplete {};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::vector<std::string> words{"dynid"};
  std::string word;
  for (size_t i = 0; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n') {
      words.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  if (!word.empty()) words.push_back(word);
  // argv strings end at the first NUL, as they would from a shell.
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);

  CLI::App app{"dynid", "dynid"};
  app.set_version_flag("--version", std::string("dynid"), "Print the version and exit");
  app.require_subcommand(1, 1);
  app.fallthrough(false);
  dynid::cli::add_commands(app);
  // The computations stay out: once a subcommand's flags are converted and its requirements
  // checked, its parse-complete callback ends the parse before the command callback could run.
  // (Replacing the command callback instead would free the options it owns while CLI11 still
  // writes to them.)
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    sub->parse_complete_callback([] { throw ParseComplete{}; });
  }
  dynid::fuzz::expect_clean([&] {
    try {
      app.parse(static_cast<int>(words.size()), argv.data());
    } catch (const CLI::Success& e) {  // --help, --version: format the text as main() would
      std::ostringstream out, err;
      app.exit(e, out, err);
    } catch (const CLI::ParseError&) {
      // Clean: main() prints it as a usage error (exit 2).
    } catch (const ParseComplete&) {
      // Clean: the command line is valid.
    }
  });
  return 0;
}
