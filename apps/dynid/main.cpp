// dynid command-line tool: see docs/cli.md. Exit codes: 0 success, 2 usage error (bad flags),
// 1 any other error. Errors are one line on stderr starting with "error:".

#include <exception>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"dynid: identification of robot dynamic parameters (see docs/cli.md)", "dynid"};
  app.set_version_flag("--version", std::string("dynid ") + dynid::kVersion,
                       "Print the version and exit");
  app.require_subcommand(1, 1);
  app.fallthrough(false);
  dynid::cli::add_model_command(app);
  dynid::cli::add_inverse_dynamics_command(app);
  dynid::cli::add_identify_command(app);
  dynid::cli::add_validate_command(app);
  dynid::cli::add_excite_command(app);
  dynid::cli::add_simulate_command(app);
  dynid::cli::add_demo_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {  // --help, --version
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "error: " << e.what() << "; run 'dynid --help' or 'dynid <command> --help'\n";
    return 2;
  } catch (const dynid::UsageError& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 2;
  } catch (const dynid::Error& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  } catch (...) {
    std::cerr << "error: unexpected failure; please report it with the command line used\n";
    return 1;
  }
  return 0;
}
