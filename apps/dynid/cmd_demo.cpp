#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/inverse_dynamics_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/model/robots.hpp"

namespace dynid::cli {
namespace {

struct DemoOptions {
  std::string out;  // optional output folder
};

/// Demo joint states for a 6-DoF arm: rest, a bent pose, and a moving pose [rad, rad/s, rad/s²].
CsvTable demo_states(const Model& model) {
  const Eigen::Index n = model.dof();
  CsvTable states;
  states.source = "demo states";
  states.columns.push_back("t");
  for (const char* prefix : {"q", "dq", "ddq"}) {
    for (Eigen::Index j = 0; j < n; ++j) states.columns.push_back(prefix + std::to_string(j + 1));
  }
  states.data = Eigen::MatrixXd::Zero(3, 1 + 3 * n);
  states.data.col(0) << 0.0, 1.0, 2.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    states.data(1, 1 + j) = (j % 2 == 0) ? 0.5 : -0.5;          // bent pose, at rest
    states.data(2, 1 + j) = 0.3;                                // moving pose
    states.data(2, 1 + n + j) = 1.0;                            // dq
    states.data(2, 1 + 2 * n + j) = (j % 2 == 0) ? 2.0 : -2.0;  // ddq
  }
  return states;
}

void run_demo(const DemoOptions& options) {
  const Model model = load_robot("puma560");
  std::cout << model_summary_text(model) << '\n';
  const CsvTable states = demo_states(model);
  const CsvTable torques = inverse_dynamics_table(model, states);
  const Eigen::IOFormat format(6, 0, "  ", "\n", "    [", "]");
  const char* labels[] = {"rest at q = 0", "bent pose at rest (q = +-0.5 rad)",
                          "moving (q = 0.3 rad, dq = 1 rad/s, ddq = +-2 rad/s^2)"};
  std::cout << "inverse dynamics (recursive Newton-Euler, joint terms included), tau [N m]\n";
  for (Eigen::Index i = 0; i < states.rows(); ++i) {
    std::cout << "  " << labels[i] << ":\n"
              << torques.data.row(i).tail(model.dof()).format(format) << '\n';
  }
  if (!options.out.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.out, ec);
    if (ec) {
      throw Error("--out " + options.out + ": cannot create the folder (" + ec.message() +
                  "); choose a writable folder");
    }
    const std::string base = options.out + "/";
    write_json(base + "model.json", model_to_json(model));
    write_csv(base + "states.csv", states.columns, states.data);
    write_csv(base + "torques.csv", torques.columns, torques.data);
    std::cout << "\nwrote " << base << "model.json, states.csv, torques.csv\n";
  }
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto options = std::make_shared<DemoOptions>();
  CLI::App* cmd = app.add_subcommand(
      "demo", "Show the built-in puma560 model and a few inverse-dynamics results");
  cmd->add_option("--out,-o", options->out,
                  "Folder for the demo files (model.json, states.csv, torques.csv); created if "
                  "missing");
  cmd->callback([options] { run_demo(*options); });
}

}  // namespace dynid::cli
