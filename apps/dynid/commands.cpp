// add_commands(): the one list of dynid's subcommands (main.cpp and fuzz/cli_fuzzer.cpp).
#include "commands.hpp"

#include "file_flags.hpp"
#include "flag_checks.hpp"

namespace dynid::cli {

void add_commands(CLI::App& app) {
  add_model_command(app);
  add_inverse_dynamics_command(app);
  add_identify_command(app);
  add_validate_command(app);
  add_excite_command(app);
  add_simulate_command(app);
  add_compare_control_command(app);
  add_average_command(app);
  add_demo_command(app);
  add_payload_command(app);
  add_export_command(app);
  add_report_command(app);
  add_run_command(app);
  add_merge_command(app);
  add_compare_command(app);
  check_numeric_flags(app);
  check_file_flags(app);
}

}  // namespace dynid::cli
