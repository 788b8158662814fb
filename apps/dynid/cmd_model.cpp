#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/identification_report.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {
namespace {

struct ModelOptions {
  std::string robot;              // built-in name or .urdf/.yaml path
  std::string json;               // optional JSON output path
  bool base = false;              // also compute the base parameters
  std::string friction = "none";  // per-joint columns classified with the link parameters
  RobotFlags robot_flags;         // --joints, --lock, --strict
};

ParameterLayout parse_layout(const std::string& text) {
  if (text == "none") return ParameterLayout::rigid();
  if (text == "full") return ParameterLayout::full();
  throw UsageError(
      "--friction for --base must be none (link parameters only) or full (with Ia, Fv, Fc, Fo)");
}

void run_model(const ModelOptions& options, const CLI::App& cmd) {
  if (!options.base && cmd.count("--friction")) {
    std::cerr << "warning: --friction has no effect without --base\n";
  }
  const Model model = load_cli_robot(options.robot, options.robot_flags, {"model", {}, {}, {}, ""});
  std::cout << model_summary_text(model);
  nlohmann::json json = model_to_json(model);
  if (options.base) {
    BaseParameterOptions base_options;
    base_options.layout = parse_layout(options.friction);
    base_options.coupling = true;
    const BaseParameters base = compute_base_parameters(model, base_options);
    std::cout << '\n' << base_parameters_text(base);
    json.update(base_parameters_to_json(base));
  }
  if (!options.json.empty()) {
    write_json(options.json, json);
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
  add_robot_flags(cmd, options->robot_flags);
  cmd->add_option("--json", options->json,
                  "Also write the model as JSON to this file (keys: name, source, dof, gravity, "
                  "joints, standard_parameters, friction, transmission, locked_joints, version)");
  cmd->add_flag("--base", options->base,
                "Also compute the base parameters (numerical Gautier-Khalil), their regrouping "
                "expressions and the parameters with no effect; JSON keys base_parameters, "
                "unidentifiable, rank");
  cmd->add_option("--friction", options->friction,
                  "With --base: none (link parameters only) or full (also Ia, Fv, Fc, Fo)")
      ->capture_default_str();
  cmd->callback([options, cmd] { run_model(*options, *cmd); });
}

}  // namespace dynid::cli
