#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/model/robots.hpp"

namespace dynid::cli {
namespace {

struct ModelOptions {
  std::string robot;  // built-in name or .urdf/.yaml path
  std::string json;   // optional JSON output path
  // A later issue adds `--base` (base parameters and regrouping): add the flag here and a section
  // to the text/JSON output in run_model.
};

void run_model(const ModelOptions& options) {
  const Model model = load_robot(options.robot);
  std::cout << model_summary_text(model);
  if (!options.json.empty()) {
    write_json(options.json, model_to_json(model));
    std::cout << "\nwrote " << options.json << '\n';
  }
}

}  // namespace

void add_model_command(CLI::App& app) {
  auto options = std::make_shared<ModelOptions>();
  CLI::App* cmd = app.add_subcommand(
      "model",
      "Print a robot model summary: joints, limits, standard parameters, friction, "
      "transmission");
  cmd->add_option(
         "--robot,-r", options->robot,
         "Built-in robot name (" +
             [] {
               std::string s;
               for (const auto& n : builtin_robot_names()) s += (s.empty() ? "" : ", ") + n;
               return s;
             }() +
             ") or a .urdf / .yaml model file")
      ->required();
  cmd->add_option("--json", options->json,
                  "Also write the model as JSON to this file (keys: name, source, dof, gravity, "
                  "joints, standard_parameters, friction, transmission, version)");
  cmd->callback([options] { run_model(*options); });
}

}  // namespace dynid::cli
