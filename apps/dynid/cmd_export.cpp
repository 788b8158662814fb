#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/physical/urdf_export.hpp"
#include "flag_checks.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {
namespace {

struct ExportOptions {
  std::string robot;       // built-in name or .urdf/.yaml path the parameters were identified on
  std::string params;      // result JSON of identify --physical
  std::string out;         // URDF to write
  RobotFlags robot_flags;  // --joints, --lock, --strict: default the ones stored in --params
};

void run_export(const ExportOptions& o) {
  namespace fs = std::filesystem;
  const fs::path folder = fs::path(o.out).parent_path();
  std::error_code ec;
  if (!folder.empty() && !fs::is_directory(folder, ec)) {
    throw Error("--out '" + o.out + "': folder '" + folder.string() +
                "' does not exist; create it or write elsewhere");
  }
  const ConsistentParameterFile file = read_consistent_parameters(o.params);
  RobotContext context{"export", {}, {}, {}, o.params};
  if (!file.locked_joints.empty()) context.stored = {file.joints, file.locked_joints};
  const Model model = load_cli_robot(o.robot, o.robot_flags, context);
  require_same_robot(file.robot, model.name, "'" + o.params + "'",
                     "export with the robot the parameters were identified on");
  if (!file.joints.empty()) {
    bool same = static_cast<int>(file.joints.size()) == model.dof();
    for (int j = 0; same && j < model.dof(); ++j) same = file.joints[j] == model.joints[j].name;
    if (!same) {
      throw Error("'" + o.params + "' names other joints than robot '" + model.name +
                  "' (--robot); export with the robot the parameters were identified on");
    }
  }
  UrdfExport exported;
  try {
    exported = export_urdf(model, file.names, file.values, o.params);
  } catch (const Error& e) {
    throw Error("'" + o.params + "': " + e.what());
  }
  write_text_atomic(o.out, exported.text);
  for (const auto& link : exported.merged_links) {
    std::cout << "link " << link << " is fixed to a moving link: its inertia is part of that "
              << "link's identified one (inertial removed)\n";
  }
  for (const auto& term : exported.not_in_urdf) std::cout << "not in the URDF: " << term << '\n';
  std::cout << "wrote " << o.out << '\n';
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto o = std::make_shared<ExportOptions>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write physically consistent identified parameters (identify --physical) as a URDF");
  cmd->add_option("--robot,-r", o->robot,
                  "Built-in robot name or .urdf/.yaml model the parameters were identified on; a "
                  "URDF (or the urdf: of a YAML model) is edited (inertials, joint <dynamics>), "
                  "other models are written with "
                  "the same frames")
      ->required();
  add_robot_flags(cmd, o->robot_flags, RobotFlagDefaults::kStoredInParams);
  cmd->add_option("--params,-p", o->params,
                  "Result JSON of 'dynid identify --physical' (its standard_parameters)")
      ->required();
  cmd->add_option("--out,-o", o->out,
                  "URDF to write: inertials (mass, centre of mass, inertia about it in the link "
                  "frame) and <dynamics damping friction>; a comment lists the identified terms "
                  "URDF cannot hold (armature, offset, asymmetric friction)")
      ->required();
  cmd->callback([o] { run_export(*o); });
}

}  // namespace dynid::cli
