// libFuzzer harness for the CLI argument layer: the input is split at newlines into argv (after
// "dynid"), parsed by CLI11 with the real subcommand definitions (apps/dynid/cmd_*.cpp). The
// subcommand callbacks are replaced by no-ops, so the harness covers flag parsing, type
// conversion and option checks, not the computations (those go through the built binary in
// tests/cli/cli_fuzz_test.cpp). Clean outcomes are the ones main.cpp maps to an exit code:
// success, --help/--version, CLI::ParseError and dynid::Error.

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "fuzz_support.hpp"

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
  dynid::cli::add_model_command(app);
  dynid::cli::add_inverse_dynamics_command(app);
  dynid::cli::add_identify_command(app);
  dynid::cli::add_validate_command(app);
  dynid::cli::add_excite_command(app);
  dynid::cli::add_simulate_command(app);
  dynid::cli::add_demo_command(app);
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    sub->callback([] {});
  }
  dynid::fuzz::expect_clean([&] {
    try {
      app.parse(static_cast<int>(words.size()), argv.data());
    } catch (const CLI::Success& e) {  // --help, --version: format the text as main() would
      std::ostringstream out, err;
      app.exit(e, out, err);
    } catch (const CLI::ParseError&) {
      // Clean: main() prints it as a usage error (exit 2).
    }
  });
  return 0;
}
