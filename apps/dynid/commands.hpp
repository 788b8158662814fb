#pragma once

// The dynid subcommands. Each file cmd_<name>.cpp registers one subcommand: parse -> validate ->
// call the library -> write results. No math here (docs/design.md section 2).

#include <string>

#include <CLI/CLI.hpp>

#include <nlohmann/json.hpp>

#include "dynid/model/model.hpp"
#include "dynid/physical/completed_model.hpp"

namespace dynid {
struct SignalOptions;
}

namespace dynid::cli {

/// Registers every subcommand below on `app`, the NaN/Inf check of their numeric flags
/// (flag_checks.hpp) and the check that no output is one of the inputs (file_flags.hpp): the one
/// definition of the command line, used by main(), `dynid run` and the CLI fuzzer.
void add_commands(CLI::App& app);

/// `dynid model`: robot summary and JSON export (cmd_model.cpp).
void add_model_command(CLI::App& app);

/// `dynid inverse-dynamics`: joint torques for every row of a states CSV
/// (cmd_inverse_dynamics.cpp).
void add_inverse_dynamics_command(CLI::App& app);

/// `dynid demo`: built-in puma560 summary and a few inverse-dynamics results (cmd_demo.cpp).
void add_demo_command(CLI::App& app);

/// `dynid identify`: base parameters with uncertainty from a recorded run (cmd_identify.cpp).
void add_identify_command(CLI::App& app);

/// `dynid validate`: prediction errors of identified parameters on another run (cmd_identify.cpp).
void add_validate_command(CLI::App& app);

/// `dynid excite`: optimised Fourier excitation (cmd_excite.cpp).
void add_excite_command(CLI::App& app);

/// `dynid simulate`: closed-loop run of a reference on a simulated robot (cmd_simulate.cpp).
void add_simulate_command(CLI::App& app);

/// `dynid average`: mean period and noise statistics of a periodic run (cmd_average.cpp).
void add_average_command(CLI::App& app);

/// `dynid payload`: a gripped load's parameters from a wrist force/torque sensor (cmd_payload.cpp).
void add_payload_command(CLI::App& app);

/// `dynid compare-control`: PID vs computed-torque tracking on one plant (cmd_compare_control.cpp).
void add_compare_control_command(CLI::App& app);

/// The model of identified base parameters in result JSON `params` (identified_model(), with the
/// friction set and armature the file records) completed where its data do not determine them
/// (complete_identified_model(): nominal values; warnings on stderr, prefixed with `command`),
/// with where each base parameter came from; with params empty the nominal model. Throws
/// dynid::Error naming the file (unreadable, another robot, a name that is no base parameter).
CompletedModel completed_model_from_result(const Model& model, const std::string& params,
                                           const std::string& command);

/// `dynid export`: physically consistent parameters written as URDF (cmd_export.cpp).
void add_export_command(CLI::App& app);
/// `dynid report`: self-contained HTML page with plots of result JSON files (cmd_report.cpp).
void add_report_command(CLI::App& app);
/// `dynid merge`: partial results of identify --stream --partial merged and solved
/// (cmd_merge.cpp).
void add_merge_command(CLI::App& app);
/// `dynid compare`: per-parameter drift between identification results (cmd_compare.cpp).
void add_compare_command(CLI::App& app);
/// `dynid run`: a whole study from a YAML project file (cmd_run.cpp, workflow/project.hpp).
void add_run_command(CLI::App& app);

}  // namespace dynid::cli
